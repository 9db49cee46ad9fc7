// `none`: renders every object, every frame — the reference cost of no culling.
#include "cullers.hpp"

namespace occull::detail {
namespace {

class NoneCuller final : public Culler {
 public:
  explicit NoneCuller(const SceneIndex& index) {
    all_.reserve(index.scene.objects().size());
    for (ObjectId id = 0; id < index.scene.objects().size(); ++id) all_.push_back(id);
  }

  FrameStats render_frame(const View&, Backend& backend) override {
    backend.render(all_);
    return {};
  }

 private:
  std::vector<ObjectId> all_;
};

}  // namespace

std::unique_ptr<Culler> make_none(const SceneIndex& index, const Options&) {
  return std::make_unique<NoneCuller>(index);
}

}  // namespace occull::detail
