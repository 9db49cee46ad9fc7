// Internal: the factory of each algorithm (one file per algorithm).
#pragma once

#include "occull/culler.hpp"

#include <memory>

namespace occull::detail {

std::unique_ptr<Culler> make_none(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_vfc(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_stopwait(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_perobject(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_chc(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_chcpp(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_nohc(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_grid(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_auto(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_tilevfc(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_pertile(const SceneIndex& index, const Options& options, const CullerContext& context);
std::unique_ptr<Culler> make_tiles(const SceneIndex& index, const Options& options, const CullerContext& context);

}  // namespace occull::detail
