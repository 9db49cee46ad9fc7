// `city`: a street grid of blocks with detailed buildings, street furniture,
// parked and driving cars, and glass bus shelters.
//
// Layout (metres, +Y up, north is -Z): `blocks` x `blocks` blocks of
// kBlock x kBlock metres separated by kStreet-wide streets. Street k's
// centre line lies at street_line(k), k = 0..blocks. Each block has a raised
// sidewalk slab and two to six buildings on lots; lamps, trees, benches and
// parked cars line the curbs; moving cars circle blocks in the lanes. The
// camera paths keep to the street centre lines, which nothing occupies.
#include "mesh_builder.hpp"
#include "scenes_internal.hpp"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace occull::scenes {
namespace {

constexpr float kBlock = 64.0f;          // block side, including the sidewalk ring
constexpr float kStreet = 16.0f;         // curb to curb
constexpr float kPitch = kBlock + kStreet;
constexpr float kSidewalk = 3.5f;        // sidewalk ring width inside a block
constexpr float kCurbHeight = 0.15f;
constexpr float kFloor = 3.2f;           // storey height
constexpr float kRecess = 0.35f;         // window recess depth
constexpr float kEye = 1.7f;             // eye height of a walker

struct CityParams {
  int blocks;
  int floors_max;
  int detail;
  int traffic;
  int shading;
  std::uint64_t seed;
};

class CityBuilder {
 public:
  CityBuilder(const CityParams& p, SceneBundle& bundle)
      : p_(p), scene_(bundle.scene), scripted_(bundle.scripted), rng_(p.seed) {
    origin_ = -0.5f * (float(p.blocks) * kPitch + kStreet);
  }

  void build() {
    make_materials();
    make_shared_meshes();
    make_roads();
    for (int i = 0; i < p_.blocks; ++i)
      for (int j = 0; j < p_.blocks; ++j) make_block(i, j);
    make_traffic();
  }

  /// Centre line of street k (k = 0..blocks), along either axis.
  [[nodiscard]] float street_line(int k) const { return origin_ + float(k) * kPitch + 0.5f * kStreet; }
  [[nodiscard]] float tallest() const { return tallest_; }

 private:
  Aabb block_bounds(int i, int j) const {
    const float x0 = origin_ + kStreet + float(i) * kPitch;
    const float z0 = origin_ + kStreet + float(j) * kPitch;
    return {{x0, 0.0f, z0}, {x0 + kBlock, kCurbHeight, z0 + kBlock}};
  }

  MaterialId material(const char* name, glm::vec3 rgb, int cost, bool translucent = false,
                      float alpha = 1.0f) {
    return scene_.add_material({name, glm::vec4(rgb, alpha), translucent, cost});
  }

  void make_materials() {
    const int s = p_.shading;
    const glm::vec3 facade_colors[] = {{0.78f, 0.72f, 0.62f}, {0.66f, 0.48f, 0.40f},
                                       {0.62f, 0.64f, 0.66f}, {0.80f, 0.78f, 0.74f},
                                       {0.55f, 0.42f, 0.34f}, {0.70f, 0.66f, 0.56f}};
    for (const auto& c : facade_colors) facades_.push_back(material("facade", c, s));
    road_ = material("asphalt", {0.22f, 0.22f, 0.24f}, s);
    sidewalk_ = material("sidewalk", {0.58f, 0.57f, 0.55f}, s);
    metal_ = material("metal", {0.30f, 0.32f, 0.35f}, s);
    foliage_ = material("foliage", {0.25f, 0.45f, 0.20f}, s);
    wood_ = material("wood", {0.42f, 0.30f, 0.20f}, s);
    glass_ = material("glass", {0.55f, 0.75f, 0.85f}, s, true, 0.35f);
    const glm::vec3 car_colors[] = {{0.70f, 0.10f, 0.10f}, {0.10f, 0.25f, 0.60f},
                                    {0.85f, 0.85f, 0.82f}, {0.12f, 0.12f, 0.13f},
                                    {0.80f, 0.65f, 0.15f}, {0.35f, 0.45f, 0.35f}};
    for (const auto& c : car_colors) cars_.push_back(material("car paint", c, s));
  }

  void make_shared_meshes() {
    {  // street lamp: pole, arm and lamp head; pole at the origin, arm towards +X
      MeshBuilder m;
      m.prism({0, 0, 0}, 0.22f, 0.4f, 8);
      m.prism({0, 0.4f, 0}, 0.09f, 5.6f, 8);
      m.box({{0.0f, 5.8f, -0.06f}, {1.4f, 5.92f, 0.06f}});
      m.box({{1.1f, 5.55f, -0.2f}, {1.6f, 5.8f, 0.2f}});
      lamp_ = scene_.add_mesh(m.take());
    }
    for (int v = 0; v < 3; ++v) {  // trees: trunk and stacked foliage cones
      MeshBuilder m;
      const float h = 5.0f + 1.5f * float(v);
      m.prism({0, 0, 0}, 0.2f, 2.0f + 0.3f * float(v), 7);
      m.cone({0, 1.8f, 0}, 2.2f + 0.3f * float(v), h * 0.55f, 12);
      m.cone({0, 1.8f + h * 0.3f, 0}, 1.7f + 0.2f * float(v), h * 0.5f, 12);
      m.cone({0, 1.8f + h * 0.55f, 0}, 1.1f, h * 0.4f, 12);
      trees_.push_back(scene_.add_mesh(m.take()));
    }
    for (int v = 0; v < 2; ++v) {  // cars: body, cabin and wheels, facing +X
      MeshBuilder m;
      const float len = v == 0 ? 4.3f : 5.0f, w = 1.8f;
      m.box({{-len / 2, 0.35f, -w / 2}, {len / 2, 1.05f, w / 2}}, MeshBuilder::no_bottom);
      m.box({{-len * 0.28f, 1.05f, -w / 2 + 0.1f}, {len * 0.2f, 1.55f, w / 2 - 0.1f}},
            MeshBuilder::no_bottom);
      for (float x : {-len * 0.32f, len * 0.32f})
        for (float z : {-w / 2 - 0.02f, w / 2 - 0.23f})
          m.cylinder_z({x, 0.34f, z}, 0.34f, 0.25f, 10);
      car_meshes_.push_back(scene_.add_mesh(m.take()));
    }
    {  // bench
      MeshBuilder m;
      m.box({{-0.9f, 0.42f, -0.22f}, {0.9f, 0.48f, 0.22f}});
      m.box({{-0.9f, 0.5f, 0.18f}, {0.9f, 0.9f, 0.24f}});
      for (float x : {-0.8f, 0.8f}) m.box({{x - 0.05f, 0.0f, -0.2f}, {x + 0.05f, 0.42f, 0.2f}});
      bench_ = scene_.add_mesh(m.take());
    }
    {  // bus shelter: frame and roof (opaque) and glass walls (translucent), facing +Z
      MeshBuilder frame;
      for (float x : {-2.0f, 2.0f})
        for (float z : {-0.7f, 0.7f}) frame.box({{x - 0.06f, 0.0f, z - 0.06f}, {x + 0.06f, 2.5f, z + 0.06f}});
      frame.box({{-2.2f, 2.5f, -0.9f}, {2.2f, 2.65f, 0.9f}});
      shelter_frame_ = scene_.add_mesh(frame.take());
      MeshBuilder glass;
      glass.box({{-2.0f, 0.1f, -0.72f}, {2.0f, 2.45f, -0.68f}});
      glass.box({{-2.02f, 0.1f, -0.68f}, {-1.98f, 2.45f, 0.6f}});
      glass.box({{1.98f, 0.1f, -0.68f}, {2.02f, 2.45f, 0.6f}});
      shelter_glass_ = scene_.add_mesh(glass.take());
    }
  }

  void make_roads() {
    // One asphalt tile per grid cell (street crossing plus the two street
    // segments beside it); blocks' sidewalk slabs sit on top.
    const int n = p_.blocks;
    for (int i = 0; i <= n; ++i)
      for (int j = 0; j <= n; ++j) {
        const float x0 = origin_ + float(i) * kPitch, z0 = origin_ + float(j) * kPitch;
        const float x1 = x0 + (i < n ? kPitch : kStreet), z1 = z0 + (j < n ? kPitch : kStreet);
        MeshBuilder m;
        m.box({{x0, -0.2f, z0}, {x1, 0.0f, z1}}, MeshBuilder::pos_y);
        scene_.add_object(scene_.add_mesh(m.take()), road_, glm::mat4(1.0f), OccluderClass::always);
      }
  }

  glm::mat4 placed(const glm::vec3& p, float yaw) const {
    return glm::rotate(glm::translate(glm::mat4(1.0f), p), yaw, glm::vec3(0, 1, 0));
  }

  void make_block(int i, int j) {
    const Aabb block = block_bounds(i, j);
    {
      MeshBuilder m;
      m.box(block, MeshBuilder::no_bottom);
      scene_.add_object(scene_.add_mesh(m.take()), sidewalk_, glm::mat4(1.0f), OccluderClass::always);
    }
    // Lots: the inner area split into 2 x 2 (sometimes 3 x 2) at random positions.
    const float x0 = block.min.x + kSidewalk, x1 = block.max.x - kSidewalk;
    const float z0 = block.min.z + kSidewalk, z1 = block.max.z - kSidewalk;
    std::vector<float> xs{x0}, zs{z0};
    const int nx = rng_.chance(0.3f) ? 3 : 2, nz = 2;
    for (int k = 1; k < nx; ++k)
      xs.push_back(x0 + (x1 - x0) * (float(k) / float(nx) + rng_.uniform(-0.08f, 0.08f)));
    for (int k = 1; k < nz; ++k)
      zs.push_back(z0 + (z1 - z0) * (float(k) / float(nz) + rng_.uniform(-0.1f, 0.1f)));
    xs.push_back(x1);
    zs.push_back(z1);
    for (std::size_t a = 0; a + 1 < xs.size(); ++a)
      for (std::size_t b = 0; b + 1 < zs.size(); ++b) {
        const Aabb lot{{xs[a] + 0.6f, kCurbHeight, zs[b] + 0.6f},
                       {xs[a + 1] - 0.6f, kCurbHeight, zs[b + 1] - 0.6f}};
        if (rng_.chance(0.08f))
          make_plaza(lot);
        else
          make_building(lot);
      }
    make_street_furniture(block);
  }

  void make_plaza(const Aabb& lot) {
    for (float x = lot.min.x + 4.0f; x < lot.max.x - 2.0f; x += 7.0f)
      for (float z = lot.min.z + 4.0f; z < lot.max.z - 2.0f; z += 7.0f) {
        // The random draws one by one, in the order GCC evaluated them as one
        // call's arguments (C++ leaves it open; GCC: right to left), so the
        // city stays as it was. The same wherever draws shared one call.
        const float yaw = rng_.uniform(0.0f, 6.28f);
        const MeshId tree = trees_[std::size_t(rng_.integer(0, 2))];
        scene_.add_object(tree, foliage_, placed({x, kCurbHeight, z}, yaw), OccluderClass::sometimes);
      }
  }

  // A building on `lot` (only x/z of lot are used): core, pilasters, floor
  // bands, window sills and lintels, roof furniture. One object.
  void make_building(const Aabb& lot) {
    const float u = rng_.uniform();
    const int floors = 3 + int(float(p_.floors_max - 3) * u * u * u + 0.5f);
    const float height = float(floors) * kFloor + 1.0f;
    tallest_ = std::max(tallest_, height);
    const float y0 = kCurbHeight;
    MeshBuilder m;
    const Aabb f{{lot.min.x, y0, lot.min.z}, {lot.max.x, y0 + height, lot.max.z}};
    m.box({{f.min.x + kRecess, y0, f.min.z + kRecess}, {f.max.x - kRecess, y0 + height - 0.2f,
                                                         f.max.z - kRecess}},
          MeshBuilder::no_bottom);
    const float bay = rng_.uniform(2.6f, 3.6f);
    for (int side = 0; side < 4; ++side) facade(m, f, side, floors, bay);
    // Roof: an elevator housing and a few machines.
    const glm::vec3 c = f.center();
    m.box({{c.x - 2.5f, f.max.y - 0.2f, c.z - 2.0f}, {c.x + 2.5f, f.max.y + 2.8f, c.z + 2.0f}},
          MeshBuilder::no_bottom);
    for (int k = rng_.integer(1, 4); k > 0; --k) {
      const float x = rng_.uniform(f.min.x + 2.0f, f.max.x - 3.5f);
      const float z = rng_.uniform(f.min.z + 2.0f, f.max.z - 3.5f);
      m.box({{x, f.max.y - 0.2f, z}, {x + 1.5f, f.max.y + 1.2f, z + 1.5f}}, MeshBuilder::no_bottom);
    }
    const MaterialId mat = facades_[std::size_t(rng_.integer(0, int(facades_.size()) - 1))];
    scene_.add_object(scene_.add_mesh(m.take()), mat, glm::mat4(1.0f), OccluderClass::always);
  }

  // Facade detail on one side of footprint f: side 0 = -Z, 1 = +X, 2 = +Z, 3 = -X.
  void facade(MeshBuilder& m, const Aabb& f, int side, int floors, float bay_target) {
    const bool along_x = side == 0 || side == 2;
    const float len = along_x ? f.max.x - f.min.x : f.max.z - f.min.z;
    const float start = along_x ? f.min.x : f.min.z;
    const float plane = side == 0 ? f.min.z : side == 1 ? f.max.x : side == 2 ? f.max.z : f.min.x;
    const float outward = (side == 1 || side == 2) ? 1.0f : -1.0f;
    // A box spanning [a, b] along the facade, [y0, y1] high, from `depth_in`
    // behind the facade plane to `depth_out` in front of it.
    const auto piece = [&](float a, float b, float y0, float y1, float depth_in, float depth_out) {
      const float p0 = plane - outward * depth_in, p1 = plane + outward * depth_out;
      const float lo = std::min(p0, p1), hi = std::max(p0, p1);
      if (along_x)
        m.box({{a, y0, lo}, {b, y1, hi}}, MeshBuilder::no_bottom);
      else
        m.box({{lo, y0, a}, {hi, y1, b}}, MeshBuilder::no_bottom);
    };
    const int bays = std::max(1, int(len / bay_target));
    const float bay = len / float(bays);
    const float pilaster = 0.55f;
    const float base = f.min.y;
    const float top = f.max.y;
    for (int k = 0; k <= bays; ++k) {
      const float c = start + float(k) * bay;
      const float a = std::max(start, c - pilaster / 2), b = std::min(start + len, c + pilaster / 2);
      piece(a, b, base, top, kRecess, 0.0f);
    }
    piece(start, start + len, base, base + 0.9f, kRecess, 0.05f);  // plinth
    piece(start, start + len, top - 0.6f, top, kRecess, 0.15f);    // cornice / parapet
    for (int fl = 1; fl < floors; ++fl) {
      const float y = base + float(fl) * kFloor;
      piece(start, start + len, y - 0.3f, y + 0.05f, kRecess, 0.0f);  // floor band
    }
    if (p_.detail < 2) return;
    for (int fl = 0; fl < floors; ++fl) {
      const float y = base + float(fl) * kFloor;
      for (int k = 0; k < bays; ++k) {
        const float a = start + float(k) * bay + pilaster / 2 + 0.2f;
        const float b = start + float(k + 1) * bay - pilaster / 2 - 0.2f;
        if (b <= a) continue;
        if (fl > 0 || p_.detail >= 3) piece(a, b, y + 0.85f, y + 0.97f, kRecess * 0.5f, 0.12f);  // sill
        if (p_.detail >= 3) piece(a, b, y + 2.45f, y + 2.6f, kRecess * 0.5f, 0.06f);           // lintel
      }
    }
  }

  void make_street_furniture(const Aabb& block) {
    // Along each side of the block, 0.9 m inside the curb: alternate lamps
    // and trees, a few benches, cars parked in the street 1.2 m off the curb.
    for (int side = 0; side < 4; ++side) {
      const bool along_x = side == 0 || side == 2;
      const float edge = side == 0 ? block.min.z : side == 1 ? block.max.x : side == 2 ? block.max.z : block.min.x;
      const float outward = (side == 1 || side == 2) ? 1.0f : -1.0f;
      const float lo = (along_x ? block.min.x : block.min.z) + 4.0f;
      const float hi = (along_x ? block.max.x : block.max.z) - 4.0f;
      const auto at = [&](float s, float off) {
        const float across = edge - outward * off;
        return along_x ? glm::vec3(s, kCurbHeight, across) : glm::vec3(across, kCurbHeight, s);
      };
      const float face_out = side == 0 ? glm::half_pi<float>() : side == 1 ? 0.0f
                           : side == 2 ? -glm::half_pi<float>() : glm::pi<float>();
      int k = 0;
      for (float s = lo; s <= hi; s += 9.0f, ++k) {
        if (k % 2 == 0)
          scene_.add_object(lamp_, metal_, placed(at(s, 0.8f), face_out), OccluderClass::never);
        else {
          const float yaw = rng_.uniform(0.0f, 6.28f);  // before the mesh (GCC's order, make_plaza)
          const MeshId tree = trees_[std::size_t(rng_.integer(0, 2))];
          scene_.add_object(tree, foliage_, placed(at(s, 1.3f), yaw), OccluderClass::sometimes);
        }
      }
      for (int b = rng_.integer(0, 2); b > 0; --b)
        scene_.add_object(bench_, wood_, placed(at(rng_.uniform(lo, hi), 2.2f), face_out + glm::pi<float>()),
                          OccluderClass::never);
      if (side == int(rng_.next() % 4)) {
        const glm::mat4 t = placed(at(0.5f * (lo + hi), 2.0f), face_out - glm::half_pi<float>());
        scene_.add_object(shelter_frame_, metal_, t, OccluderClass::never);
        scene_.add_object(shelter_glass_, glass_, t, OccluderClass::never);
      }
      // Parked cars in the street, parallel to the curb.
      const float along_yaw = along_x ? 0.0f : glm::half_pi<float>();
      for (float s = lo + 2.0f; s <= hi - 2.0f; s += 6.5f) {
        if (!rng_.chance(0.45f)) continue;
        const float across = edge + outward * 1.3f;
        const glm::vec3 pos = along_x ? glm::vec3(s, 0.0f, across) : glm::vec3(across, 0.0f, s);
        const MaterialId paint = cars_[std::size_t(rng_.integer(0, int(cars_.size()) - 1))];  // GCC's order
        const MeshId car = car_meshes_[std::size_t(rng_.integer(0, 1))];
        scene_.add_object(car, paint, placed(pos, along_yaw), OccluderClass::sometimes);
      }
    }
  }

  void make_traffic() {
    // Each moving car circles one block counter-clockwise (seen from above)
    // in the lane 4 m off its curb.
    for (int c = 0; c < p_.traffic; ++c) {
      const int i = rng_.integer(0, p_.blocks - 1), j = rng_.integer(0, p_.blocks - 1);
      const Aabb b = block_bounds(i, j).grown(4.0f);
      Motion motion;
      motion.waypoints = {{b.min.x, 0.0f, b.min.z}, {b.min.x, 0.0f, b.max.z},
                          {b.max.x, 0.0f, b.max.z}, {b.max.x, 0.0f, b.min.z}};
      motion.speed = rng_.uniform(6.0f, 12.0f);
      motion.start_offset = rng_.uniform(0.0f, 4.0f * (kBlock + 8.0f));
      // The paint drawn before the mesh (GCC's order, make_plaza).
      const MaterialId paint = cars_[std::size_t(rng_.integer(0, int(cars_.size()) - 1))];
      const MeshId car = car_meshes_[std::size_t(rng_.integer(0, 1))];
      add_scripted_object(scene_, scripted_, car, paint, std::move(motion), OccluderClass::sometimes);
    }
  }

  CityParams p_;
  Scene& scene_;
  std::vector<ScriptedObject>& scripted_;
  Rng rng_;
  float origin_ = 0.0f;
  float tallest_ = 0.0f;
  std::vector<MaterialId> facades_, cars_;
  MaterialId road_ = 0, sidewalk_ = 0, metal_ = 0, foliage_ = 0, wood_ = 0, glass_ = 0;
  MeshId lamp_ = 0, bench_ = 0, shelter_frame_ = 0, shelter_glass_ = 0;
  std::vector<MeshId> trees_, car_meshes_;
};

CameraPath::Key key(double t, glm::vec3 p, float yaw_deg, float pitch_deg = 0.0f) {
  return {t, {p, glm::radians(yaw_deg), glm::radians(pitch_deg)}, false};
}

// Appends a straight walk from the last key to `to` at `speed` m/s.
void walk_to(std::vector<CameraPath::Key>& keys, glm::vec3 to, float yaw_deg, float speed,
             float pitch_deg = 0.0f) {
  const auto& last = keys.back();
  const double d = glm::length(to - last.pose.position);
  keys.push_back(key(last.time + std::max(d / speed, 0.5), to, yaw_deg, pitch_deg));
}

// Turns in place to `yaw_deg` over `seconds`.
void turn_to(std::vector<CameraPath::Key>& keys, float yaw_deg, double seconds,
             float pitch_deg = 0.0f) {
  const auto& last = keys.back();
  keys.push_back(key(last.time + seconds, last.pose.position, yaw_deg, pitch_deg));
}

std::vector<CameraPath> city_paths(const CityBuilder& city, int blocks) {
  const auto line = [&](int k) { return city.street_line(k); };
  const int mid = blocks / 2;
  const float walk_speed = 7.0f;
  std::vector<CameraPath> paths;
  {  // street: north along the middle street, east, north again.
    const int north = std::max(0, blocks - 3);
    const int east = std::min(blocks, mid + 2);
    std::vector<CameraPath::Key> k{key(0.0, {line(mid), kEye, line(blocks)}, 0.0f)};
    walk_to(k, {line(mid), kEye, line(north)}, 0.0f, walk_speed);
    turn_to(k, -90.0f, 1.5);
    walk_to(k, {line(east), kEye, line(north)}, -90.0f, walk_speed);
    turn_to(k, 0.0f, 1.5);
    walk_to(k, {line(east), kEye, line(std::max(0, north - 1))}, 0.0f, walk_speed);
    paths.emplace_back("street", "walk at eye height along streets through several blocks", k);
  }
  {  // flyover: rise above the roofs, cross the city, come back down.
    const float high = city.tallest() + 35.0f;
    const float z_start = line(blocks), z_end = line(0);
    const float x = line(mid);
    std::vector<CameraPath::Key> k{key(0.0, {x, kEye, z_start}, 0.0f)};
    walk_to(k, {x, kEye, z_start - 0.5f * kPitch}, 0.0f, walk_speed);
    walk_to(k, {x, high, z_start - 1.2f * kPitch}, 0.0f, 12.0f, -20.0f);
    walk_to(k, {x, high, z_end + 1.2f * kPitch}, 0.0f, 25.0f, -25.0f);
    walk_to(k, {x, kEye, z_end + 0.5f * kPitch}, 0.0f, 12.0f, 0.0f);
    walk_to(k, {x, kEye, z_end}, 0.0f, walk_speed);
    paths.emplace_back("flyover", "rises above the roofs and comes back down (sudden visibility changes)", k);
  }
  {  // turn: fast turns at a crossing in the middle of the city.
    const glm::vec3 p{line(mid), kEye, line(mid)};
    std::vector<CameraPath::Key> k{key(0.0, p, 0.0f)};
    for (float yaw : {120.0f, 240.0f, 360.0f}) turn_to(k, yaw, 1.0);
    turn_to(k, 270.0f, 0.8, 8.0f);
    turn_to(k, 180.0f, 0.8, -5.0f);
    turn_to(k, 90.0f, 0.8);
    for (float yaw : {0.0f, -120.0f, -240.0f, -360.0f}) turn_to(k, yaw, 0.6);
    paths.emplace_back("turn", "fast turns in place at a crossing", k);
  }
  return paths;
}

}  // namespace

SceneInfo city_info() {
  return {"city",
          "a street grid of blocks: detailed facades, lamps, trees, parked and driving cars, "
          "glass bus shelters",
          {{"blocks", 8, 3, 40, true, "blocks along each side of the square city"},
           {"floors", 24, 4, 80, true, "most storeys of a building (heights are skewed low)"},
           {"detail", 2, 1, 3, true, "facade detail: 1 pilasters and bands, 2 + sills, 3 + lintels"},
           {"traffic", 60, 0, 2000, true, "cars driving around blocks (dynamic objects)"},
           {"shading", 0, 0, 64, true, "light evaluations per fragment (fragment cost)"},
           {"seed", 1, 0, 1e9, true, "random seed"}},
          {"street", "flyover", "turn"}};
}

SceneBundle make_city(const Params& params) {
  CityParams p;
  p.blocks = int(params.at("blocks"));
  p.floors_max = int(params.at("floors"));
  p.detail = int(params.at("detail"));
  p.traffic = int(params.at("traffic"));
  p.shading = int(params.at("shading"));
  p.seed = std::uint64_t(params.at("seed"));
  SceneBundle bundle{Scene("city"), {}, Lens{60.0f, 0.1f, 1500.0f}};
  CityBuilder builder(p, bundle);
  builder.build();
  bundle.paths = city_paths(builder, p.blocks);
  bundle.lens.far = std::max(1500.0f, 1.5f * float(p.blocks) * kPitch);
  return bundle;
}

}  // namespace occull::scenes
