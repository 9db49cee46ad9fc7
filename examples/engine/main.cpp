// A small engine that culls with occull: its own meshes, shaders and draw
// loop over plain OpenGL 4.5 (not occull's renderer), its own objects moved,
// added and removed by its game logic every frame, its own reversed-Z view
// with an infinite far plane, and CHC++ deciding what to draw.
//
// The README's integration section quotes the parts between the
// "[readme: NAME]" and "[readme end]" lines; a test checks that it does.
//
// It checks itself: after every frame, occull's ground truth (an id-buffer
// pass of gl::Renderer over a copy of the scene with vertices) lists the
// objects with a visible pixel, and each must be among those the culler
// drew. Exit 0: no object missed; 1: a miss or a query left in flight;
// 2: bad arguments; 3: no OpenGL 4.5.
//
//   occull_example_engine [--algo SPEC] [--frames N] [--size WxH]
#include <occull/configs.hpp>
#include <occull/culler.hpp>
#include <occull/error.hpp>
#include <occull/gl/context.hpp>
#include <occull/gl/renderer.hpp>

#include <GL/gl.h>
#include <GL/glext.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

// ---------------------------------------------------------------------------
// The engine's own data: meshes on the device, objects with a model matrix.

struct CpuMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;
  std::vector<std::uint32_t> indices;
};

// A unit cube [-0.5, 0.5]^3 (scaled per object) or an octagonal pillar;
// each side a grid of 8 x 8 quads, as meshes of some detail are.
CpuMesh make_mesh(bool pillar) {
  CpuMesh m;
  const auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    constexpr std::uint32_t kGrid = 8;
    const auto base = std::uint32_t(m.positions.size());
    for (std::uint32_t i = 0; i <= kGrid; ++i)
      for (std::uint32_t j = 0; j <= kGrid; ++j) {
        const float u = float(i) / kGrid, v = float(j) / kGrid;  // a -> d along u, a -> b along v
        m.positions.push_back(glm::mix(glm::mix(a, b, v), glm::mix(d, c, v), u));
        m.normals.push_back(n);
      }
    for (std::uint32_t i = 0; i < kGrid; ++i)
      for (std::uint32_t j = 0; j < kGrid; ++j) {
        const std::uint32_t k = base + i * (kGrid + 1) + j, up = k + 1, next = k + kGrid + 1;
        m.indices.insert(m.indices.end(), {k, up, next + 1, k, next + 1, next});
      }
  };
  const int sides = pillar ? 8 : 4;
  std::vector<glm::vec2> ring;
  for (int i = 0; i < sides; ++i) {
    const float a = 6.2831853f * (float(i) + 0.5f) / float(sides);
    // Corners on a circle whose polygon's sides touch the unit square's (|x|, |z| <= 0.5).
    const float r = 0.5f / std::cos(3.14159265f / float(sides));
    ring.emplace_back(std::cos(a) * r, std::sin(a) * r);
  }
  for (int i = 0; i < sides; ++i) {
    const glm::vec2 p = ring[std::size_t(i)], q = ring[std::size_t((i + 1) % sides)];
    quad({p.x, -0.5f, p.y}, {p.x, 0.5f, p.y}, {q.x, 0.5f, q.y}, {q.x, -0.5f, q.y});  // outward, counter-clockwise
  }
  // Caps as fans (counter-clockwise seen from outside).
  for (const float y : {-0.5f, 0.5f}) {
    const auto base = std::uint32_t(m.positions.size());
    for (const glm::vec2& p : ring) {
      m.positions.emplace_back(p.x, y, p.y);
      m.normals.emplace_back(0.0f, y > 0 ? 1.0f : -1.0f, 0.0f);
    }
    for (std::uint32_t i = 1; i + 1 < std::uint32_t(sides); ++i) {
      if (y > 0)
        m.indices.insert(m.indices.end(), {base, base + i + 1, base + i});
      else
        m.indices.insert(m.indices.end(), {base, base + i, base + i + 1});
    }
  }
  return m;
}

struct GpuMesh {
  GLuint vao = 0, buffers[2] = {0, 0};
  GLsizei indices = 0;
};

GpuMesh upload(const CpuMesh& m) {
  GpuMesh g;
  std::vector<float> interleaved;
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    interleaved.insert(interleaved.end(), {m.positions[i].x, m.positions[i].y, m.positions[i].z, m.normals[i].x,
                                           m.normals[i].y, m.normals[i].z});
  glCreateBuffers(2, g.buffers);
  glNamedBufferStorage(g.buffers[0], GLsizeiptr(interleaved.size() * sizeof(float)), interleaved.data(), 0);
  glNamedBufferStorage(g.buffers[1], GLsizeiptr(m.indices.size() * 4), m.indices.data(), 0);
  glCreateVertexArrays(1, &g.vao);
  glVertexArrayVertexBuffer(g.vao, 0, g.buffers[0], 0, 6 * sizeof(float));
  glVertexArrayElementBuffer(g.vao, g.buffers[1]);
  for (GLuint a = 0; a < 2; ++a) {
    glEnableVertexArrayAttrib(g.vao, a);
    glVertexArrayAttribFormat(g.vao, a, 3, GL_FLOAT, GL_FALSE, a * 3 * sizeof(float));
    glVertexArrayAttribBinding(g.vao, a, 0);
  }
  g.indices = GLsizei(m.indices.size());
  return g;
}

GLuint compile(const char* vertex, const char* fragment) {
  const auto stage = [](GLenum type, const char* source) {
    const GLuint s = glCreateShader(type);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) throw std::runtime_error("shader does not compile");
    return s;
  };
  const GLuint program = glCreateProgram();
  const GLuint vs = stage(GL_VERTEX_SHADER, vertex), fs = stage(GL_FRAGMENT_SHADER, fragment);
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  return program;
}

struct EngineObject {
  int mesh = 0;  // 0 cube, 1 pillar
  glm::mat4 model{1.0f};
  bool crate = false;  // moved by the game logic
  float phase = 0.0f;
};

// ---------------------------------------------------------------------------
// The engine's side of occull: draw the objects occull asks for, and run
// occlusion queries over boxes. Each call sets the state it relies on.
class EngineBackend final : public occull::Backend {
 public:
  EngineBackend(const std::vector<EngineObject>& objects, const std::vector<GpuMesh>& meshes)
      : objects_(objects), meshes_(meshes) {
    draw_program_ = compile(R"(#version 450
      layout(location = 0) in vec3 p; layout(location = 1) in vec3 n;
      uniform mat4 view_proj, model; out vec3 normal;
      void main() { normal = mat3(model) * n; gl_Position = view_proj * model * vec4(p, 1.0); })",
                            R"(#version 450
      in vec3 normal; out vec4 colour;
      void main() { colour = vec4(vec3(0.3 + 0.6 * abs(normalize(normal).y)), 1.0); })");
    box_program_ = compile(R"(#version 450
      uniform mat4 view_proj; uniform vec3 lo, hi;
      void main() {  // the 36 corners of a box's 12 triangles, from the vertex index
        const int c[36] = int[](0,2,3, 0,3,1, 4,5,7, 4,7,6, 0,1,5, 0,5,4, 2,6,7, 2,7,3, 0,4,6, 0,6,2, 1,3,7, 1,7,5);
        int k = c[gl_VertexID];
        vec3 t = vec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
        gl_Position = view_proj * vec4(mix(lo, hi, t), 1.0); })",
                           R"(#version 450
      void main() {})");
    glCreateVertexArrays(1, &empty_vao_);
    model_ = glGetUniformLocation(draw_program_, "model");
    lo_ = glGetUniformLocation(box_program_, "lo");
    hi_ = glGetUniformLocation(box_program_, "hi");
  }

  // Call at the start of the engine's frame, after binding its target.
  void begin_frame(const glm::mat4& view_proj) {
    view_proj_ = view_proj;
    state_ = State::none;  // other GL code may have run since: set state again
  }

  // [readme: backend]
  void render(std::span<const occull::ObjectId> ids) override {
    enter(State::draw);
    for (occull::ObjectId id : ids) {
      const EngineObject& o = objects_[id];
      glUniformMatrix4fv(model_, 1, GL_FALSE, glm::value_ptr(o.model));
      glBindVertexArray(meshes_[std::size_t(o.mesh)].vao);
      glDrawElements(GL_TRIANGLES, meshes_[std::size_t(o.mesh)].indices, GL_UNSIGNED_INT, nullptr);
      ++stats_.draw_calls;
      ++stats_.objects_rendered;
    }
    ++stats_.render_flushes;
  }

  occull::QueryId issue_query(std::span<const occull::Aabb> boxes) override {
    enter(State::query);
    occull::QueryId q;
    if (free_.empty()) {
      GLuint name = 0;
      glCreateQueries(GL_SAMPLES_PASSED, 1, &name);
      names_.push_back(name);
      live_.push_back(false);
      q = occull::QueryId(names_.size() - 1);
    } else {
      q = free_.back();
      free_.pop_back();
    }
    live_[q] = true;
    glBeginQuery(GL_SAMPLES_PASSED, names_[q]);
    for (const occull::Aabb& b : boxes) {
      // A hair larger than the box: rasterisers snap vertices to sub-pixels.
      const glm::vec3 margin = 0.002f * (b.max - b.min) + glm::vec3(0.002f);
      glUniform3fv(lo_, 1, glm::value_ptr(b.min - margin));
      glUniform3fv(hi_, 1, glm::value_ptr(b.max + margin));
      glDrawArrays(GL_TRIANGLES, 0, 36);
    }
    glEndQuery(GL_SAMPLES_PASSED);
    ++stats_.queries;
    stats_.query_boxes += boxes.size();
    return q;
  }

  bool result_available(occull::QueryId q) override {
    check(q);
    GLuint available = GL_FALSE;
    glGetQueryObjectuiv(names_[q], GL_QUERY_RESULT_AVAILABLE, &available);
    return available == GL_TRUE;
  }

  std::uint64_t result(occull::QueryId q) override {
    check(q);
    GLuint64 samples = 0;
    glGetQueryObjectui64v(names_[q], GL_QUERY_RESULT, &samples);
    live_[q] = false;
    free_.push_back(q);
    return samples;
  }

  void flush() override { glFlush(); }
  [[nodiscard]] occull::BackendStats stats() const override { return stats_; }
  // [readme end]
  [[nodiscard]] std::size_t queries_in_flight() const { return names_.size() - free_.size(); }

 private:
  enum class State { none, draw, query };

  // [readme: state]
  // Reversed-Z: nearer is greater. Query boxes test against what was drawn
  // without writing, both faces (the eye may be inside a box), clamped at the
  // near plane (a box crossing it still counts), pulled toward the eye.
  void enter(State s) {
    if (state_ == s) return;
    state_ = s;
    const bool draw = s == State::draw;
    const GLuint program = draw ? draw_program_ : box_program_;
    glUseProgram(program);
    glUniformMatrix4fv(glGetUniformLocation(program, "view_proj"), 1, GL_FALSE, glm::value_ptr(view_proj_));
    if (!draw) glBindVertexArray(empty_vao_);
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(draw ? GL_GREATER : GL_GEQUAL);
    glDepthMask(draw ? GL_TRUE : GL_FALSE);
    glColorMask(draw, draw, draw, draw);
    if (draw) glEnable(GL_CULL_FACE); else glDisable(GL_CULL_FACE);
    if (draw) glDisable(GL_DEPTH_CLAMP); else glEnable(GL_DEPTH_CLAMP);
    if (draw) glDisable(GL_POLYGON_OFFSET_FILL); else glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(1.0f, 2.0f);  // toward the eye under reversed-Z
  }
  // [readme end]

  void check(occull::QueryId q) const {
    if (q >= live_.size() || !live_[q]) throw std::logic_error("EngineBackend: query not in flight");
  }

  const std::vector<EngineObject>& objects_;
  const std::vector<GpuMesh>& meshes_;
  GLuint draw_program_ = 0, box_program_ = 0, empty_vao_ = 0;
  GLint model_ = -1, lo_ = -1, hi_ = -1;
  glm::mat4 view_proj_{1.0f};
  State state_ = State::none;
  std::vector<GLuint> names_;
  std::vector<bool> live_;
  std::vector<occull::QueryId> free_;
  occull::BackendStats stats_;
};

// Reversed-Z with an infinite far plane: depth = near / distance.
glm::mat4 reversed_infinite(float fov_y, float aspect, float near) {
  glm::mat4 p(0.0f);
  const float f = 1.0f / std::tan(fov_y / 2.0f);
  p[0][0] = f / aspect;
  p[1][1] = f;
  p[2][3] = -1.0f;
  p[3][2] = near;
  return p;
}

struct Args {
  std::string algo;  // a spec; empty: the engine's own typed config (chcpp, batch 20)
  int frames = 120;
  int width = 320, height = 180;
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--algo" && i + 1 < argc) {
      a.algo = argv[++i];
    } else if (arg == "--frames" && i + 1 < argc) {
      a.frames = std::atoi(argv[++i]);
    } else if (arg == "--size" && i + 1 < argc) {
      if (std::sscanf(argv[++i], "%dx%d", &a.width, &a.height) != 2) throw occull::InputError("--size WIDTHxHEIGHT");
    } else if (arg == "--help" || arg == "-h") {
      std::printf("occull_example_engine [--algo SPEC] [--frames N] [--size WxH]: a small engine culling with "
                  "occull (chcpp with batches of 20 by default), checked against occull's ground truth (exit 0: nothing missed)\n");
      std::exit(0);
    } else {
      throw occull::InputError("unknown argument " + arg + " (--algo NAME, --frames N, --size WxH, --help)");
    }
  }
  if (a.frames < 1 || a.width < 16 || a.height < 16 || a.width > 4096 || a.height > 4096)
    throw occull::InputError("--frames must be >= 1 and --size within 16x16 .. 4096x4096");
  return a;
}

int run(const Args& args) {
  auto context = occull::gl::Context::create();  // the engine's window would be here

  // The engine's meshes, on the device and, for occull, as bounds only.
  const CpuMesh cpu_meshes[2] = {make_mesh(false), make_mesh(true)};
  std::vector<GpuMesh> meshes = {upload(cpu_meshes[0]), upload(cpu_meshes[1])};
  std::vector<EngineObject> objects;

  // [readme: scene]
  // occull's view of the engine's objects: boxes, triangle counts, classes.
  occull::Scene scene("engine");
  const occull::MaterialId opaque = scene.add_material({});
  occull::MeshId mesh_ids[2];
  for (int m = 0; m < 2; ++m)
    mesh_ids[m] = scene.add_mesh(occull::MeshInfo{{glm::vec3(-0.5f), glm::vec3(0.5f)},
                                                  std::uint32_t(cpu_meshes[m].indices.size() / 3), 6.0});
  // [readme end]

  // The ground truth's copy of the scene, with vertices, ids kept in step.
  occull::Scene truth_scene("engine truth");
  const occull::MaterialId truth_material = truth_scene.add_material({});
  occull::MeshId truth_meshes[2];
  for (int m = 0; m < 2; ++m) {
    occull::Mesh mesh;
    mesh.positions = cpu_meshes[m].positions;
    mesh.normals = cpu_meshes[m].normals;
    mesh.indices = cpu_meshes[m].indices;
    truth_meshes[m] = truth_scene.add_mesh(std::move(mesh));
  }

  const auto add = [&](int mesh, const glm::mat4& model, bool crate, occull::OccluderClass cls) {
    // [readme: add]
    const occull::ObjectId id = scene.add_object(mesh_ids[mesh], opaque, model, cls);  // reuses removed ids
    // [readme end]
    const occull::ObjectId twin = truth_scene.add_object(truth_meshes[mesh], truth_material, model, cls);
    if (id != twin) throw std::logic_error("the truth's copy lost step with the scene");
    if (id >= objects.size()) objects.resize(id + 1);
    objects[id] = {mesh, model, crate, float(id) * 0.37f};
    return id;
  };
  const auto remove = [&](occull::ObjectId id) {
    // [readme: remove]
    scene.remove_object(id);  // its id keeps an empty slot until add_object reuses it
    // [readme end]
    truth_scene.remove_object(id);
  };
  const auto box = [](glm::vec3 centre, glm::vec3 size) {
    return glm::scale(glm::translate(glm::mat4(1.0f), centre), size);
  };

  // A town: ground, 10 x 10 blocks of buildings and pillars, crates on the streets.
  add(0, box({0, -0.5f, 0}, {400, 1, 400}), false, occull::OccluderClass::always);
  for (int bx = -5; bx < 5; ++bx)
    for (int bz = -5; bz < 5; ++bz) {
      const float h = 6.0f + float((bx * 7 + bz * 13 + 100) % 9) * 3.0f;
      const glm::vec3 c(float(bx) * 20.0f + 10.0f, h / 2.0f, float(bz) * 20.0f + 10.0f);
      add((bx + bz) % 4 == 0 ? 1 : 0, box(c, {12, h, 12}), false, occull::OccluderClass::always);
    }
  std::vector<occull::ObjectId> crates;
  for (int i = 0; i < 60; ++i) crates.push_back(add(0, glm::mat4(1.0f), true, occull::OccluderClass::never));

  // [readme: frame]
  occull::Bvh bvh = occull::Bvh::build(scene);
  // The engine's choice in a typed config (a misspelt field does not compile); --algo picks another
  // by its spec at run time ("nohc", "chcpp:batch=20", ...).
  auto culler = args.algo.empty() ? occull::make_culler(occull::ChcppConfig{.batch = 20}, {scene, bvh})
                                  : occull::make_culler(args.algo, {scene, bvh});
  EngineBackend backend(objects, meshes);
  // [readme end]

  // The engine's render target.
  GLuint fbo = 0, colour = 0, depth = 0;
  glCreateRenderbuffers(1, &colour);
  glNamedRenderbufferStorage(colour, GL_RGBA8, args.width, args.height);
  glCreateRenderbuffers(1, &depth);
  glNamedRenderbufferStorage(depth, GL_DEPTH_COMPONENT32F, args.width, args.height);
  glCreateFramebuffers(1, &fbo);
  glNamedFramebufferRenderbuffer(fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
  glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);

  occull::gl::RendererOptions truth_options;
  truth_options.width = args.width;
  truth_options.height = args.height;
  std::unique_ptr<occull::gl::Renderer> truth;
  std::size_t truth_objects = 0;  // objects of truth_scene when `truth` was made

  std::uint64_t missed = 0, drawn = 0, visible = 0, queries = 0, rebuilds = 0;
  unsigned rng = 12345;
  const auto next = [&rng] { return rng = rng * 1664525u + 1013904223u; };
  for (int frame = 0; frame < args.frames; ++frame) {
    const float t = float(frame) / 30.0f;
    // Game logic: crates drive along the streets; some are destroyed, some spawned.
    for (std::size_t i = 0; i < crates.size(); ++i) {
      EngineObject& o = objects[crates[i]];
      const float street = float(int(i % 10) - 5) * 20.0f;
      const float along = std::fmod(o.phase * 40.0f + t * (4.0f + float(i % 5)), 200.0f) - 100.0f;
      const glm::vec3 at = i % 2 ? glm::vec3(street, 1.0f, along) : glm::vec3(along, 1.0f, street);
      o.model = box(at, {2, 2, 2});
      // [readme: move]
      scene.set_transform(crates[i], o.model);
      // [readme end]
      truth_scene.set_transform(crates[i], o.model);
    }
    if (frame % 10 == 5) {  // two crates destroyed, two spawned (their ids reused)
      for (int k = 0; k < 2; ++k) {
        const std::size_t i = next() % crates.size();
        remove(crates[i]);
        crates[i] = add(0, box({0, 1, 0}, {2, 2, 2}), true, occull::OccluderClass::never);
      }
    }
    if (frame % 40 == 20) crates.push_back(add(0, box({0, 1, 0}, {2, 2, 2}), true, occull::OccluderClass::never));

    // The engine's camera: a walk down a street, looking around.
    const glm::vec3 eye(-0.5f, 1.7f, -90.0f + t * 6.0f);
    const float yaw = 0.6f * std::sin(t * 0.7f);
    const glm::mat4 view_matrix = glm::lookAt(eye, eye + glm::vec3(std::sin(yaw), -0.05f, std::cos(yaw)), {0, 1, 0});
    const glm::mat4 proj = reversed_infinite(1.0f, float(args.width) / float(args.height), 0.1f);

    // [readme: cull]
    const occull::View view = occull::make_view(view_matrix, proj, args.width, args.height,
                                                {occull::DepthRange::zero_to_one, /*reversed_z=*/true});
    const std::uint64_t generation = bvh.generation();
    bvh.refit(scene);  // follows set_transform, add_object, remove_object
    // the engine starts its frame: target, viewport, clip conventions, clear
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, args.width, args.height);
    glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
    glClearDepth(0.0);  // reversed-Z: 0 is the far end
    glClearColor(0.5f, 0.6f, 0.7f, 1.0f);
    glDepthMask(GL_TRUE);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    backend.begin_frame(view.view_proj);
    const occull::FrameResult result = culler->render_frame(view, backend);  // objects drawn, queries, nodes, CPU ms
    const std::span<const occull::ObjectId> drawn_set = culler->drawn_objects();  // for shadows, LOD, streaming
    // [readme end]
    glFinish();
    rebuilds += bvh.generation() != generation ? 1 : 0;
    queries += result.queries;
    drawn += drawn_set.size();

    // occull's ground truth: every object with a visible pixel must be drawn.
    if (truth_scene.objects().size() != truth_objects) {  // objects added: occull's renderer needs a new one
      truth = std::make_unique<occull::gl::Renderer>(truth_scene, truth_options);
      truth_objects = truth_scene.objects().size();
    }
    std::vector<occull::ObjectId> in_frustum;
    for (occull::ObjectId id = 0; id < truth_scene.objects().size(); ++id)
      if (truth_scene.alive(id) && view.frustum.classify(truth_scene.object(id).bounds) != occull::Containment::outside)
        in_frustum.push_back(id);
    for (const auto& v : truth->visible_pixels(view, in_frustum)) {
      ++visible;
      if (!std::binary_search(drawn_set.begin(), drawn_set.end(), v.id)) {
        ++missed;
        std::printf("frame %d: object %u visible (%u pixels) but not drawn\n", frame, v.id, v.pixels);
      }
    }
  }
  // [readme: release]
  culler->release(backend);  // reads or drops every query the culler still holds
  // [readme end]
  const std::size_t left = backend.queries_in_flight();
  std::printf("engine: %d frames at %dx%d, %zu objects, %llu hierarchy rebuilds; per frame %.1f drawn, %.1f "
              "visible, %.1f queries; missed %llu object-frames; %zu queries left in flight\n",
              args.frames, args.width, args.height, scene.objects().size(), (unsigned long long)rebuilds,
              double(drawn) / args.frames, double(visible) / args.frames, double(queries) / args.frames,
              (unsigned long long)missed, left);
  if (visible == 0) {
    std::printf("engine: the truth saw nothing: the check would prove nothing\n");
    return 1;
  }
  return missed == 0 && left == 0 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const occull::InputError& e) {
    std::fprintf(stderr, "occull_example_engine: %s\n", e.what());
    return 2;
  } catch (const occull::GlUnavailable& e) {
    std::fprintf(stderr, "occull_example_engine: %s\n", e.what());
    return 3;
  }
}
