// Internal: the registration of each algorithm (one file per algorithm):
// its name, summary, option table and factory (config_table.hpp).
#pragma once

#include "config_table.hpp"

#include <span>

namespace occull::detail {

Registration none_registration();
Registration vfc_registration();
Registration stopwait_registration();
Registration perobject_registration();
Registration chc_registration();
Registration chcpp_registration();
Registration nohc_registration();
Registration grid_registration();
Registration hiz_registration();
Registration soc_registration();
Registration auto_registration();
Registration tilevfc_registration();
Registration pertile_registration();
Registration tiles_registration();

/// A culler that can start its next frame from another culler's visible
/// set (auto's hand-over: chc, chcpp, nohc, hiz). `drawn` is what the other
/// culler drew in the frame before (Culler::drawn_objects()); the next
/// render_frame() takes it as its own last frame's visibility. Any set is
/// conservative: what it claims hidden is tested (queried or tested
/// against a depth pyramid) before it is culled.
class Resumable {
 public:
  virtual void resume_from(std::span<const ObjectId> drawn) = 0;
  /// For handing over from this culler when drawn_objects() is empty because
  /// its visible set is elsewhere (hiz: on the device): appends the visible
  /// set of its last frame to `out`, through `backend` (a read-back that
  /// waits for the device). Default: nothing (drawn_objects() holds it).
  virtual void last_visible(Backend& backend, std::vector<ObjectId>& out) { (void)backend, (void)out; }

 protected:
  ~Resumable() = default;
};

/// nohc's hardware profile for a culler: the file `file` names (the option
/// nohc.profile), else the device's, both from `context.hardware_profile`. Throws
/// InputError when there is none, the file does not exist, or nothing
/// reads files.
HardwareProfile nohc_profile(const CullerContext& context, const std::string& file);

}  // namespace occull::detail
