// The reference renderer's instrument side: the untimed truth pass
// (visible_pixels, samples_in_front) over the same scene resources as the
// frame passes, and the read-backs of its targets. Each pass sets the
// state it relies on (prepare_pass), as the frame passes do.
#include "occull/gl/renderer.hpp"

#include "renderer_impl.hpp"

#include <algorithm>

namespace occull::gl {

std::vector<std::uint32_t> Renderer::read_ids() const {
  const Impl& g = *impl_;
  std::vector<std::uint32_t> ids(std::size_t(g.options.width) * std::size_t(g.options.height));
  glNamedFramebufferReadBuffer(g.fbo, GL_COLOR_ATTACHMENT1);
  bind_for_reading(g.fbo, 4);
  glReadPixels(0, 0, g.options.width, g.options.height, GL_RED_INTEGER, GL_UNSIGNED_INT, ids.data());
  check_error("reading the id buffer");
  return ids;
}

std::vector<std::uint8_t> Renderer::read_rgba() const {
  const Impl& g = *impl_;
  return read_rgba_top_first(g.fbo, g.options.width, g.options.height);
}

// Draws `ids` against the depth buffer as it stands, writing nothing, and
// returns the samples that pass (the scene pass's depth test). Not counted.
std::uint64_t Renderer::Impl::samples_passing(std::span<const ObjectId> ids) {
  BackendStats ignored;
  enter_render_state(ignored);
  glDepthMask(GL_FALSE);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glBeginQuery(GL_SAMPLES_PASSED, truth_query);
  draw_objects(ids, ignored);
  glEndQuery(GL_SAMPLES_PASSED);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  GLuint64 n = 0;
  glBindBuffer(GL_QUERY_BUFFER, 0);
  glGetQueryObjectui64v(truth_query, GL_QUERY_RESULT, &n);
  return n;
}

std::uint64_t Renderer::samples_in_front(const View& view, std::span<const ObjectId> objects) {
  Impl& g = *impl_;
  g.prepare_pass(view);
  const std::uint64_t n = objects.empty() ? 0 : g.samples_passing(objects);
  glFinish();
  g.conditional.clear();
  check_error("counting samples in front of the depth buffer");
  return n;
}

std::vector<float> Renderer::read_stored_depth() const {
  const Impl& g = *impl_;
  std::vector<float> depth(std::size_t(g.options.width) * std::size_t(g.options.height));
  bind_for_reading(g.fbo, 4);
  glReadPixels(0, 0, g.options.width, g.options.height, GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
  check_error("reading the depth buffer");
  return depth;
}

std::vector<float> Renderer::read_depth() const {
  std::vector<float> depth = read_stored_depth();
  if (impl_->clip.reversed_z)  // canonical: 0 nearest, 1 farthest and nothing
    for (float& d : depth) d = 1.0f - d;
  return depth;
}

std::vector<Renderer::ObjectPixels> Renderer::visible_pixels(const View& view,
                                                             std::span<const ObjectId> objects,
                                                             PassImages* images) {
  Impl& g = *impl_;
  const BackendStats saved_stats = stats_;
  const bool saved_ids = g.write_ids;
  set_write_ids(true);
  begin_frame(view);
  std::vector<ObjectId> translucent;
  g.split_translucent(objects, translucent);  // in the order given, not sorted by material
  g.draw_objects(g.opaque, stats_);

  std::vector<std::uint64_t> samples(translucent.size());
  for (std::size_t i = 0; i < translucent.size(); ++i)
    samples[i] = g.samples_passing(std::span<const ObjectId>(&translucent[i], 1));
  end_frame();

  std::vector<std::uint32_t> ids = read_ids();
  g.pixel_counts.assign(g.scene.objects().size(), 0);
  for (std::uint32_t v : ids)
    if (v != 0) ++g.pixel_counts[v - 1];
  if (images) {
    images->ids = std::move(ids);
    images->depth = read_depth();
  }
  for (std::size_t i = 0; i < translucent.size(); ++i)
    g.pixel_counts[translucent[i]] = std::uint32_t(std::min<std::uint64_t>(samples[i], 0xffffffffu));
  std::vector<ObjectPixels> visible;
  for (ObjectId id = 0; id < g.pixel_counts.size(); ++id)
    if (g.pixel_counts[id] > 0) visible.push_back({id, g.pixel_counts[id]});

  set_write_ids(saved_ids);
  g.conditional.clear();
  stats_ = saved_stats;
  return visible;
}

}  // namespace occull::gl
