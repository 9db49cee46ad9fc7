// `none`: renders every object, every frame — the reference cost of no culling.
#include "cullers.hpp"

namespace occull::detail {
namespace {

class NoneCuller final : public Culler {
 public:
  explicit NoneCuller(const SceneIndex& index) : scene_(index.scene) {}

  FrameResult cull(const View&, Backend& backend) override {
    if (!listed_ || layout_ != scene_.layout_revision()) {  // objects added or removed
      all_.clear();
      for (ObjectId id = 0; id < scene_.objects().size(); ++id)
        if (scene_.alive(id)) all_.push_back(id);
      layout_ = scene_.layout_revision();
      listed_ = true;
    }
    backend.render(all_);
    return {};
  }

 private:
  const Scene& scene_;
  std::vector<ObjectId> all_;  // every object alive
  std::uint64_t layout_ = 0;
  bool listed_ = false;
};

}  // namespace

Registration none_registration() {
  static const ConfigTable<NoneConfig> table;
  return registered({"none", "render every object (reference cost of no culling)", true, {}, false, SceneKind::any},
                    table, [](const SceneIndex& index, const NoneConfig&, const Options&, const CullerContext&) {
                      return std::make_unique<NoneCuller>(index);
                    });
}

}  // namespace occull::detail
