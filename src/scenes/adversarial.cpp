// `adversarial`: scenes built to make a conservative culler miss a visible
// object — the shapes where a query box is not safely larger than what it
// bounds, or where the camera is where queries stop working.
//
// Every kind stands on the same stage: a flat ground of exactly touching
// tiles and walls (some of zero thickness, some in pairs with a narrow slit
// between them) to occlude and half-occlude things. Then, by `kind`:
//   tiny      thousands of small meshes of 10-30 triangles, on the ground, on
//             wall tops and just peeking out from behind wall ends;
//   thin      flat decals lying exactly on the ground or 1 mm above it, road
//             markings, kerbs, zero-thickness panels and glass, thin poles —
//             boxes of zero thickness, whose outline is exactly the object's;
//   coplanar  boxes stacked and side by side sharing faces, objects with
//             identical boxes, panels flush against wall faces;
//   near      poles a few centimetres beside the walk path at eye height (the
//             near plane cuts them as the camera passes), gates the path goes
//             under, boxes it goes through, a low ceiling;
//   far       objects of about one pixel 0.8-3 km away, flat strips among
//             them, seen across the ground and through the slits;
//   farout    zero-thickness panels with objects of 1-5 cm hidden a hand's
//             width behind them and peeking a few millimetres past their
//             edges, and the whole stage, its paths too, 3 km out from the
//             scene's own origin: float precision at work (with the scene's
//             `offset`, kilometres to thousands of them from the world's);
//   mixed     all of the above but farout (the default).
// Paths: `walk` at eye height through the near objects, `graze` 0.4 m above
// the ground looking along it, `far` along the stage's edge turning full
// circle.
#include "mesh_builder.hpp"
#include "scenes_internal.hpp"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace occull::scenes {
namespace {

enum Kind { mixed, tiny, thin, coplanar, near, far, farout, kind_count };
const char* const kKindNames[] = {"mixed", "tiny", "thin", "coplanar", "near", "far", "farout"};

constexpr float kFarOut = 3000.0f;  // farout: the stage's distance from the scene's origin along x and z, metres

constexpr float kStage = 300.0f;   // side of the square stage, metres
constexpr float kEye = 1.6f;

struct Materials {
  MaterialId ground, wall, prop, decal, glass, far_away;
};

// Everything the generator places: the scene plus what it needs to know to
// place more (the walls, the walk path).
struct Stage {
  Scene& scene;
  Rng& rng;
  Materials m;
  struct Wall {
    glm::vec3 a, b;  // ends of the wall's base line (y = 0)
    float height, thickness;
  };
  std::vector<Wall> walls;
  std::vector<glm::vec3> walk;  // eye positions of the walk path's keys
  glm::vec3 out{0.0f};          // where the stage stands in the scene (farout: far from its origin)

  ObjectId add(Mesh mesh, MaterialId material, OccluderClass cls, const glm::mat4& t = glm::mat4(1.0f)) {
    return scene.add_object(scene.add_mesh(std::move(mesh)), material, glm::translate(glm::mat4(1.0f), out) * t, cls);
  }
  glm::vec2 random_spot(float margin = 0.0f) {
    const float h = 0.5f * kStage - margin;
    return {rng.uniform(-h, h), rng.uniform(-h, h)};
  }
};

glm::mat4 placed(glm::vec3 at, float yaw) {
  return glm::rotate(glm::translate(glm::mat4(1.0f), at), yaw, glm::vec3(0, 1, 0));
}

// A quad in the XZ plane of size w x d centred at the origin, facing +Y.
Mesh flat_quad(float w, float d) {
  MeshBuilder b;
  b.quad({-0.5f * w, 0, -0.5f * d}, {0.5f * w, 0, -0.5f * d}, {0.5f * w, 0, 0.5f * d},
         {-0.5f * w, 0, 0.5f * d}, {0, 1, 0});
  return b.take();
}

// A vertical quad in the XY plane (zero thickness along Z), facing +Z.
Mesh panel(float w, float h) {
  MeshBuilder b;
  b.quad({-0.5f * w, 0, 0}, {0.5f * w, 0, 0}, {0.5f * w, h, 0}, {-0.5f * w, h, 0}, {0, 0, 1});
  return b.take();
}

// A small mesh of 10-30 triangles: a capped prism or a cone.
Mesh small_mesh(Rng& rng, float size) {
  MeshBuilder b;
  // The random draws one by one, in the order GCC evaluated them as one
  // call's arguments (C++ leaves it open; GCC: right to left), so the scenes
  // stay as they were. The same below wherever draws shared one call.
  if (rng.chance(0.5f)) {
    const int sides = rng.integer(4, 10);
    b.prism({0, 0, 0}, 0.5f * size, size * rng.uniform(0.4f, 1.6f), sides);
  } else {
    const int sides = rng.integer(5, 15);
    b.cone({0, 0, 0}, 0.5f * size, size * rng.uniform(0.5f, 2.0f), sides);
  }
  return b.take();
}

void build_ground(Stage& s) {
  constexpr int tiles = 12;
  const float t = kStage / tiles;
  for (int j = 0; j < tiles; ++j)
    for (int i = 0; i < tiles; ++i) {
      const float x = -0.5f * kStage + float(i) * t, z = -0.5f * kStage + float(j) * t;
      MeshBuilder b;  // exactly touching: shared edges, one plane
      b.quad({x, 0, z}, {x + t, 0, z}, {x + t, 0, z + t}, {x, 0, z + t}, {0, 1, 0});
      s.add(b.take(), s.m.ground, OccluderClass::always);
    }
}

void build_walls(Stage& s) {
  for (int n = 0; n < 48; ++n) {
    const glm::vec2 c = s.random_spot(20.0f);
    const float length = s.rng.uniform(4.0f, 30.0f);
    const float height = s.rng.uniform(2.0f, 10.0f);
    const bool along_x = s.rng.chance(0.5f);
    const glm::vec3 dir = along_x ? glm::vec3(1, 0, 0) : glm::vec3(0, 0, 1);
    const glm::vec3 side = along_x ? glm::vec3(0, 0, 1) : glm::vec3(1, 0, 0);
    const glm::vec3 a = glm::vec3(c.x, 0, c.y) - 0.5f * length * dir;
    const glm::vec3 b = a + length * dir;
    const int style = s.rng.integer(0, 3);
    const auto wall = [&](glm::vec3 from, glm::vec3 to, float thickness) {
      MeshBuilder mb;
      const Aabb box{glm::min(from, to) - 0.5f * thickness * side, glm::max(from, to) + 0.5f * thickness * side +
                                                                        glm::vec3(0, height, 0)};
      if (thickness > 0.0f) {
        mb.box(box, MeshBuilder::no_bottom);
      } else {  // zero thickness: its two faces, back to back
        mb.box(box, along_x ? (MeshBuilder::neg_z | MeshBuilder::pos_z) : (MeshBuilder::neg_x | MeshBuilder::pos_x));
      }
      s.add(mb.take(), s.m.wall, OccluderClass::always);
      s.walls.push_back({from, to, height, thickness});
    };
    if (style == 0) {
      wall(a, b, 0.0f);
    } else if (style == 1) {  // two walls with a slit of 5-30 cm between them
      const float gap = s.rng.uniform(0.05f, 0.3f);
      const glm::vec3 mid = 0.5f * (a + b);
      wall(a, mid - 0.5f * gap * dir, 0.3f);
      wall(mid + 0.5f * gap * dir, b, 0.3f);
    } else {
      wall(a, b, 0.3f);
    }
  }
}

void build_tiny(Stage& s, int count) {
  for (int n = 0; n < count; ++n) {
    const float size = s.rng.uniform(0.03f, 0.4f);
    Mesh mesh = small_mesh(s.rng, size);
    const float yaw = s.rng.uniform(0.0f, glm::two_pi<float>());
    const float where = s.rng.uniform();
    glm::vec3 at;
    if (where < 0.6f || s.walls.empty()) {
      const glm::vec2 p = s.random_spot();
      at = {p.x, s.rng.chance(0.2f) ? s.rng.uniform(0.5f, 3.0f) : 0.0f, p.y};
    } else {
      const Stage::Wall& w = s.walls[std::size_t(s.rng.integer(0, int(s.walls.size()) - 1))];
      if (where < 0.8f) {  // on top of the wall
        at = glm::mix(w.a, w.b, s.rng.uniform()) + glm::vec3(0, w.height, 0);
      } else {  // behind a wall end, poking out past it by a few centimetres
        const glm::vec3 dir = glm::normalize(w.b - w.a);
        const glm::vec3 side(-dir.z, 0, dir.x);
        const bool at_b = s.rng.chance(0.5f);
        // One draw per statement, in the order GCC evaluated the one expression
        // (glm's operators are calls: their arguments right to left).
        const float height = s.rng.uniform(0.0f, w.height);
        const float off = 0.5f * w.thickness + s.rng.uniform(0.3f, 3.0f);
        const float sign = s.rng.chance(0.5f) ? 1.0f : -1.0f;
        const float along = s.rng.uniform(-0.5f, 0.05f) * size;
        at = (at_b ? w.b : w.a) + (at_b ? 1.0f : -1.0f) * dir * along + side * sign * off + glm::vec3(0, height, 0);
      }
    }
    s.add(std::move(mesh), s.m.prop, OccluderClass::never, placed(at, yaw));
  }
}

void build_thin(Stage& s, int count) {
  for (int n = 0; n < count; ++n) {
    const glm::vec2 p = s.random_spot();
    const float kind = s.rng.uniform();
    const bool axis_aligned = s.rng.chance(0.5f);
    const float yaw = axis_aligned ? glm::half_pi<float>() * float(s.rng.integer(0, 3))
                                   : s.rng.uniform(0.0f, glm::two_pi<float>());
    if (kind < 0.3f) {  // decal on the ground, exactly coplanar or 1 mm above
      const float y = s.rng.chance(0.5f) ? 0.0f : 0.001f;
      const float depth = s.rng.uniform(0.3f, 3.0f);  // drawn before the width (GCC's order, above)
      const float width = s.rng.uniform(0.3f, 3.0f);
      s.add(flat_quad(width, depth), s.m.decal, OccluderClass::never, placed({p.x, y, p.y}, yaw));
    } else if (kind < 0.5f) {  // road marking: long, narrow, flat
      const float depth = s.rng.uniform(2.0f, 6.0f);  // drawn before the width (GCC's order, above)
      const float width = s.rng.uniform(0.1f, 0.15f);
      s.add(flat_quad(width, depth), s.m.decal, OccluderClass::never, placed({p.x, 0.002f, p.y}, yaw));
    } else if (kind < 0.65f) {  // kerb
      MeshBuilder b;
      const float len = s.rng.uniform(2.0f, 10.0f);
      b.box({{-0.1f, 0.0f, -0.5f * len}, {0.1f, 0.15f, 0.5f * len}}, MeshBuilder::no_bottom);
      s.add(b.take(), s.m.prop, OccluderClass::sometimes, placed({p.x, 0, p.y}, yaw));
    } else if (kind < 0.85f) {  // single-sided panel or glass, zero thickness when axis-aligned
      const bool glass = s.rng.chance(0.2f);
      // GCC's order (above): the height, then the panel's second and first side.
      const float height = s.rng.uniform(0.0f, 1.5f);
      const float second = s.rng.uniform(0.3f, 2.0f);
      const float first = s.rng.uniform(0.3f, 2.0f);
      s.add(panel(first, second), glass ? s.m.glass : s.m.prop, OccluderClass::never,
            placed({p.x, height, p.y}, yaw));
    } else {  // thin pole
      MeshBuilder b;
      const float w = s.rng.uniform(0.02f, 0.06f);
      b.box({{-0.5f * w, 0, -0.5f * w}, {0.5f * w, s.rng.uniform(1.0f, 4.0f), 0.5f * w}}, MeshBuilder::no_bottom);
      s.add(b.take(), s.m.prop, OccluderClass::never, placed({p.x, 0, p.y}, yaw));
    }
  }
}

void build_coplanar(Stage& s, int count) {
  int made = 0;
  while (made < count) {
    const glm::vec2 p = s.random_spot(5.0f);
    const float kind = s.rng.uniform();
    const float size = s.rng.uniform(0.3f, 2.0f);
    if (kind < 0.35f) {  // a stack of boxes, each on the one below
      const int n = s.rng.integer(2, 5);
      float y = 0.0f;
      for (int k = 0; k < n && made < count; ++k, ++made) {
        const float h = s.rng.uniform(0.2f, 1.0f);
        MeshBuilder b;
        b.box({{p.x, y, p.y}, {p.x + size, y + h, p.y + size}});
        s.add(b.take(), s.m.prop, OccluderClass::sometimes);
        y += h;
      }
    } else if (kind < 0.6f) {  // a row of boxes sharing faces
      const int n = s.rng.integer(2, 6);
      for (int k = 0; k < n && made < count; ++k, ++made) {
        MeshBuilder b;
        b.box({{p.x + float(k) * size, 0, p.y}, {p.x + float(k + 1) * size, size, p.y + size}});
        s.add(b.take(), s.m.prop, OccluderClass::sometimes);
      }
    } else if (kind < 0.75f) {  // two objects with the very same box
      MeshBuilder a, b;
      const Aabb box{{p.x, 0, p.y}, {p.x + size, size, p.y + size}};
      a.box(box);
      b.prism({p.x + 0.5f * size, 0, p.y + 0.5f * size}, 0.5f * size, size, 4);  // corners on the box's faces
      s.add(a.take(), s.m.prop, OccluderClass::sometimes);
      s.add(b.take(), s.m.decal, OccluderClass::never);
      made += 2;
    } else if (!s.walls.empty()) {  // a panel flush against a wall face, or 1 mm off it
      const Stage::Wall& w = s.walls[std::size_t(s.rng.integer(0, int(s.walls.size()) - 1))];
      const glm::vec3 dir = glm::normalize(w.b - w.a);
      const glm::vec3 normal(-dir.z, 0, dir.x);
      const float sign = s.rng.chance(0.5f) ? 1.0f : -1.0f;
      const float off = 0.5f * w.thickness + (s.rng.chance(0.5f) ? 0.0f : 0.001f);
      const float height = s.rng.uniform(0.0f, std::max(0.0f, w.height - size));  // before `along` (GCC's order)
      const float along = s.rng.uniform(0.1f, 0.9f);
      const glm::vec3 at = glm::mix(w.a, w.b, along) + sign * off * normal + glm::vec3(0, height, 0);
      const float yaw = std::atan2(sign * normal.x, sign * normal.z);  // panel faces +Z before the turn
      s.add(panel(size, size), s.m.decal, OccluderClass::never, placed(at, yaw));
      ++made;
    } else {
      ++made;
    }
  }
}

void build_near(Stage& s, int count) {
  // Along the walk path: the camera passes through and beside these.
  for (int made = 0; made < count;) {
    const std::size_t k = std::size_t(s.rng.integer(0, int(s.walk.size()) - 2));
    const glm::vec3 a = s.walk[k], b = s.walk[k + 1];
    const glm::vec3 at = glm::mix(a, b, s.rng.uniform());
    const glm::vec3 dir = glm::normalize(b - a);
    const glm::vec3 side(-dir.z, 0, dir.x);
    const float kind = s.rng.uniform();
    if (kind < 0.5f) {  // a pole 2-50 cm beside the eye
      MeshBuilder mb;
      const float w = s.rng.uniform(0.02f, 0.1f);
      const float sign = s.rng.chance(0.5f) ? 1.0f : -1.0f;  // one draw per statement (GCC's order)
      const float lateral = sign * s.rng.uniform(0.02f, 0.5f);
      const glm::vec3 p = at + lateral * side;
      mb.box({{p.x - 0.5f * w, 0, p.z - 0.5f * w}, {p.x + 0.5f * w, kEye + s.rng.uniform(-0.3f, 1.5f), p.z + 0.5f * w}},
             MeshBuilder::no_bottom);
      s.add(mb.take(), s.m.prop, OccluderClass::never);
      ++made;
    } else if (kind < 0.7f) {  // a gate the path goes under: two posts and a lintel just above the eye
      const float half = s.rng.uniform(0.3f, 1.2f), top = kEye + s.rng.uniform(0.05f, 0.6f);
      for (float sgn : {-1.0f, 1.0f}) {
        MeshBuilder mb;
        const glm::vec3 p = at + sgn * half * side;
        mb.box({{p.x - 0.1f, 0, p.z - 0.1f}, {p.x + 0.1f, top, p.z + 0.1f}}, MeshBuilder::no_bottom);
        s.add(mb.take(), s.m.prop, OccluderClass::sometimes);
      }
      MeshBuilder lintel;
      const glm::vec3 l0 = at - (half + 0.1f) * side, l1 = at + (half + 0.1f) * side;
      const glm::vec3 lo = glm::min(l0, l1) - glm::vec3(0.1f), hi = glm::max(l0, l1) + glm::vec3(0.1f);
      lintel.box({{lo.x, top, lo.z}, {hi.x, top + 0.2f, hi.z}});
      s.add(lintel.take(), s.m.prop, OccluderClass::sometimes);
      made += 3;
    } else if (kind < 0.9f) {  // a box the eye passes through
      MeshBuilder mb;
      const float r = s.rng.uniform(0.3f, 2.0f);
      const float dz = s.rng.uniform(-0.5f, 0.5f) * r;  // before dx (GCC's order, above)
      const float dx = s.rng.uniform(-0.5f, 0.5f) * r;
      const glm::vec3 c = at + glm::vec3(dx, 0, dz);
      mb.box({{c.x - r, std::max(0.0f, c.y - r), c.z - r}, {c.x + r, c.y + r, c.z + r}});
      s.add(mb.take(), s.m.prop, OccluderClass::sometimes);
      ++made;
    } else {  // a low ceiling slab just above the eye
      MeshBuilder mb;
      const float len = s.rng.uniform(2.0f, 8.0f), y = kEye + s.rng.uniform(0.05f, 0.4f);
      const glm::vec3 p0 = at - 2.0f * side, p1 = at + 2.0f * side + len * dir;
      mb.box({glm::vec3(std::min(p0.x, p1.x), y, std::min(p0.z, p1.z)), glm::vec3(std::max(p0.x, p1.x), y + 0.1f, std::max(p0.z, p1.z))});
      s.add(mb.take(), s.m.wall, OccluderClass::always);
      ++made;
    }
  }
}

void build_far(Stage& s, int count) {
  for (int n = 0; n < count; ++n) {
    const float angle = s.rng.uniform(0.0f, glm::two_pi<float>());
    const float dist = s.rng.uniform(800.0f, 3000.0f);
    const glm::vec3 at(dist * std::cos(angle), s.rng.chance(0.3f) ? s.rng.uniform(0.0f, 30.0f) : 0.0f,
                       dist * std::sin(angle));
    const float size = s.rng.uniform(0.5f, 5.0f);
    const float yaw = s.rng.chance(0.5f) ? glm::half_pi<float>() * float(s.rng.integer(0, 3))
                                         : s.rng.uniform(0.0f, glm::two_pi<float>());
    const float kind = s.rng.uniform();
    if (kind < 0.4f)
      s.add(small_mesh(s.rng, size), s.m.far_away, OccluderClass::never, placed(at, yaw));
    else if (kind < 0.7f)  // a flat strip lying on the ground: zero thickness
      s.add(flat_quad(size, s.rng.uniform(0.05f, 0.5f) * size), s.m.decal, OccluderClass::never,
            placed({at.x, 0.0f, at.z}, yaw));
    else  // a panel facing the stage
      s.add(panel(size, s.rng.uniform(0.2f, 1.0f) * size), s.m.far_away, OccluderClass::never,
            placed(at, std::atan2(-at.x, -at.z)));
  }
}

// Thin occluders and tiny objects: a zero-thickness panel (one-sided,
// facing +Z before its yaw) with objects of 1-5 cm a few centimetres to a
// hand's width behind it, peeking past its side edges by millimetres, and
// lying on its top edge.
void build_farout(Stage& s, int count) {
  for (int made = 0; made < count;) {
    const glm::vec2 c = s.random_spot(10.0f);
    const float w = s.rng.uniform(1.0f, 4.0f), h = s.rng.uniform(0.8f, 3.0f);
    const float yaw = s.rng.chance(0.5f) ? glm::half_pi<float>() * float(s.rng.integer(0, 3))
                                         : s.rng.uniform(0.0f, glm::two_pi<float>());
    const glm::mat4 at = placed({c.x, 0.0f, c.y}, yaw);
    s.add(panel(w, h), s.m.wall, OccluderClass::always, at);
    ++made;
    for (int k = 0; k < 8 && made < count; ++k, ++made) {
      const float size = s.rng.uniform(0.01f, 0.05f);
      const float where = s.rng.uniform();
      glm::vec3 local;
      if (where < 0.5f) {  // behind it
        local = {s.rng.uniform(-0.45f, 0.45f) * w, s.rng.uniform(0.0f, h - size), -s.rng.uniform(0.02f, 0.3f)};
      } else if (where < 0.85f) {  // behind a side edge, peeking past it by 0.5-3 mm
        const float sign = s.rng.chance(0.5f) ? 1.0f : -1.0f;  // one draw per statement (GCC's order)
        const float peek = s.rng.uniform(0.0005f, 0.003f);
        local = {sign * (0.5f * w + peek - 0.5f * size), s.rng.uniform(0.0f, h - size), -s.rng.uniform(0.01f, 0.1f)};
      } else {  // on its top edge, just behind it
        local = {s.rng.uniform(-0.45f, 0.45f) * w, h, -0.5f * size - 0.001f};
      }
      s.add(small_mesh(s.rng, size), s.m.prop, OccluderClass::never, at * placed(local, s.rng.uniform(0.0f, 6.3f)));
    }
  }
}

CameraPath::Key key_at(double t, glm::vec3 eye, float yaw, float pitch = 0.0f) {
  return {t, {eye, yaw, pitch}, false};
}

// Yaw that looks from a to b (0 looks down -Z).
float yaw_towards(glm::vec3 a, glm::vec3 b) { return std::atan2(-(b.x - a.x), -(b.z - a.z)); }

}  // namespace

SceneInfo adversarial_info() {
  SceneInfo info{"adversarial",
                 "scenes built to make conservative culling miss: tiny meshes, zero-thickness boxes, "
                 "coplanar and touching objects, the camera through boxes, one-pixel objects kilometres away, "
                 "thin panels hiding centimetre objects kilometres from the origin",
                 {{"kind", 0, 0, double(kind_count - 1), true, "which attack (see README)", {}},
                  {"objects", 3000, 10, 100000, true, "objects of the attack, besides the stage"},
                  {"seed", 1, 0, 1e9, true, "random seed"}},
                 {"walk", "graze", "far"}};
  info.params[0].choices.assign(std::begin(kKindNames), std::end(kKindNames));
  return info;
}

SceneBundle make_adversarial(const Params& params) {
  const auto kind = Kind(int(params.at("kind")));
  const int count = int(params.at("objects"));
  Rng rng(std::uint64_t(params.at("seed")) * 7919u + std::uint64_t(kind));
  SceneBundle bundle{Scene(std::string("adversarial:") + kKindNames[kind]), {}, Lens{60.0f, 0.1f, 4000.0f}};
  Scene& scene = bundle.scene;
  Stage s{scene, rng,
          {scene.add_material({"ground", {0.45f, 0.47f, 0.42f, 1}, false, 0}),
           scene.add_material({"wall", {0.75f, 0.70f, 0.62f, 1}, false, 0}),
           scene.add_material({"prop", {0.80f, 0.35f, 0.25f, 1}, false, 0}),
           scene.add_material({"decal", {0.95f, 0.95f, 0.90f, 1}, false, 0}),
           scene.add_material({"glass", {0.55f, 0.80f, 1.00f, 0.35f}, true, 0}),
           scene.add_material({"far", {0.20f, 0.25f, 0.85f, 1}, false, 0})},
          {},
          {}};

  if (kind == farout) s.out = glm::vec3(kFarOut, 0.0f, kFarOut);
  // The walk path first: the near objects are placed along it.
  const float h = 0.5f * kStage;
  for (int k = 0; k <= 10; ++k) {
    const float f = float(k) / 10.0f;
    s.walk.emplace_back(-0.85f * h + 1.7f * h * f, kEye, -0.6f * h + 1.2f * h * f + 12.0f * std::sin(f * 7.0f));
  }
  build_ground(s);
  build_walls(s);
  const auto share = [&](Kind k) { return kind == k ? count : (kind == mixed && k != farout ? count / 5 : 0); };
  build_tiny(s, share(tiny));
  build_thin(s, share(thin));
  build_coplanar(s, share(coplanar));
  build_near(s, share(near));
  build_far(s, share(far));
  build_farout(s, share(farout));

  {
    std::vector<CameraPath::Key> keys;
    for (std::size_t k = 0; k < s.walk.size(); ++k) {
      const glm::vec3 next = s.walk[std::min(k + 1, s.walk.size() - 1)];
      const glm::vec3 prev = s.walk[k == 0 ? 0 : k - 1];
      keys.push_back(key_at(2.0 * double(k), s.walk[k], yaw_towards(prev == next ? s.walk[k] : prev, next)));
    }
    keys.front().pose.yaw = yaw_towards(s.walk[0], s.walk[1]);
    bundle.paths.emplace_back("walk", "at eye height through gates, boxes and past poles a hand's width away",
                              std::move(keys));
  }
  {
    std::vector<CameraPath::Key> keys;
    for (int k = 0; k <= 10; ++k) {
      const float f = float(k) / 10.0f;
      const glm::vec3 eye(-0.9f * h + 1.8f * h * f, 0.4f, 0.7f * h - 1.4f * h * f);
      keys.push_back(key_at(2.0 * k, eye, glm::radians(-135.0f) + 0.6f * std::sin(f * 5.0f), glm::radians(-1.5f)));
    }
    bundle.paths.emplace_back("graze", "0.4 m above the ground, looking along it over decals and markings",
                              std::move(keys));
  }
  {
    std::vector<CameraPath::Key> keys;
    for (int k = 0; k <= 12; ++k) {
      const float f = float(k) / 12.0f;
      const glm::vec3 eye(0.8f * h, 2.0f, -0.2f * h + 0.4f * h * f);
      keys.push_back(key_at(2.0 * k, eye, glm::two_pi<float>() * f, glm::radians(0.5f)));
    }
    bundle.paths.emplace_back("far", "walks along the stage's edge turning full circle, looking out at "
                              "one-pixel objects kilometres away",
                              std::move(keys));
  }
  if (s.out != glm::vec3(0.0f))  // the paths stand where the stage does
    for (CameraPath& p : bundle.paths) {
      std::vector<CameraPath::Key> keys = p.keys();
      for (CameraPath::Key& k : keys) k.pose.position += s.out;
      p = CameraPath(p.name(), p.description(), std::move(keys));
    }
  return bundle;
}

}  // namespace occull::scenes
