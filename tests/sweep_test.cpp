// Option sweeps: settings from --vary axes, the choice of the best one.
#include "occull/error.hpp"
#include "occull/sweep.hpp"

#include <gtest/gtest.h>

using namespace occull;

TEST(Sweep, SettingsAreEveryCombinationTheLastAxisFastest) {
  const SweepAxis axes[] = {parse_sweep_axis("grid", "cap=250,4000"), parse_sweep_axis("grid", "cell=2,4,8")};
  EXPECT_EQ(sweep_specs("grid", axes),
            (std::vector<std::string>{"grid:cap=250:cell=2", "grid:cap=250:cell=4", "grid:cap=250:cell=8",
                                      "grid:cap=4000:cell=2", "grid:cap=4000:cell=4", "grid:cap=4000:cell=8"}));
}

TEST(Sweep, MalformedAxesAndTooManySettingsAreInputErrors) {
  for (const char* bad : {"cap", "cap=", "=4", "cap=1,,2", "cap=1,1", "cap=1:2", "nope=1"})
    EXPECT_THROW((void)parse_sweep_axis("grid", bad), InputError) << bad;
  EXPECT_THROW((void)parse_sweep_axis("no_such_algorithm", "cap=1"), InputError);
  try {
    (void)parse_sweep_axis("grid", "nope=1");
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vis_duration"), std::string::npos) << "lists the valid options";
  }
  const SweepAxis twice[] = {parse_sweep_axis("grid", "cap=1"), parse_sweep_axis("grid", "cap=2")};
  EXPECT_THROW((void)sweep_specs("grid", twice), InputError);
  EXPECT_THROW((void)sweep_specs("grid", {}), InputError);
  const SweepAxis big[] = {parse_sweep_axis("grid", "cap=1,2,3,4,5,6,7,8,9"),
                           parse_sweep_axis("grid", "cell=1,2,3,4,5,6,7,8")};
  EXPECT_THROW((void)sweep_specs("grid", big), InputError) << "72 settings";
}

TEST(Sweep, BestIsTheFastestSettingWithinThePoppingLimit) {
  const auto row = [](const char* name, double mean_ms, std::uint64_t missed, std::uint32_t longest) {
    AlgorithmSummary a;
    a.name = name;
    a.frame_ms.mean = mean_ms;
    a.missed_objects = missed;
    a.truth_object_frames = 10000;
    a.longest_miss_frames = longest;
    return a;
  };
  const AlgorithmSummary fast_pops = row("fast", 5.0, 50, 2);       // 0.5 %: too many
  const AlgorithmSummary long_miss = row("long", 6.0, 5, 4);        // one object missed 4 frames
  const AlgorithmSummary ok_slow = row("ok slow", 9.0, 10, 3);      // 0.1 %, 3 frames: within
  const AlgorithmSummary ok_fast = row("ok fast", 8.0, 0, 0);
  const AlgorithmSummary* rows[] = {&fast_pops, &long_miss, &ok_slow, &ok_fast};
  EXPECT_EQ(best_setting(rows, {}, true), &ok_fast);
  const AlgorithmSummary* without_fast[] = {&fast_pops, &long_miss, &ok_slow};
  EXPECT_EQ(best_setting(without_fast, {}, true), &ok_slow);
  EXPECT_EQ(best_setting(rows, {0.01, 3}, true), &fast_pops) << "a looser limit";
  EXPECT_EQ(best_setting(rows, {}, false), nullptr) << "no popping figures without verification";
  const AlgorithmSummary* none_ok[] = {&fast_pops, &long_miss};
  EXPECT_EQ(best_setting(none_ok, {}, true), nullptr);
}
