// occull soak: its windows, its figures, and the verdicts on growth.
#include "occull/error.hpp"
#include "occull/soak.hpp"
#include "gl_test_util.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sstream>

using namespace occull;

namespace {

SoakConfig tiny() {
  SoakConfig c;
  c.scene = "city:blocks=3,traffic=3";
  c.frames = 40;
  c.window = 20;
  c.warmup = 4;
  c.renderer = test::small_target(64, 36);
  return c;
}

// A window's end: `queries` in the pool, `held` of them in flight.
SoakWindow window(std::uint64_t resident, std::size_t queries, std::size_t held = 0) {
  SoakWindow w;
  w.median_ms = 1.0;
  w.resident_bytes = resident;
  w.gl.queries = queries;
  w.gl.queries_free = queries - held;
  w.gl.buffer_bytes = 1000;
  return w;
}

}  // namespace

TEST(Soak, RunsEveryAlgorithmOverItsWindowsOnTheTurnPathReportingMemoryAndGlObjects) {
  std::ostringstream live;
  const SoakResult r = run_soak(tiny(), {}, &live);
  EXPECT_EQ(r.path, "turn");
  ASSERT_EQ(r.runs.size(), 3u);
  for (const SoakRun& run : r.runs) {
    ASSERT_EQ(run.windows.size(), 2u) << run.algorithm;
    EXPECT_EQ(run.windows[1].first_frame, 20);
    for (const SoakWindow& w : run.windows) {
      EXPECT_GT(w.median_ms, 0.0) << run.algorithm;
      EXPECT_GT(w.resident_bytes, 0u) << run.algorithm;
#if defined(__SANITIZE_ADDRESS__)
      // AddressSanitizer's allocator is not glibc's heap: mallinfo2 knows nothing (0: unknown).
      EXPECT_EQ(w.heap_held_bytes, 0u) << run.algorithm;
#else
      EXPECT_GT(w.heap_bytes, 0u) << run.algorithm;
      EXPECT_GE(w.heap_held_bytes, w.heap_bytes) << run.algorithm << ": the heap holds at least what is in use";
#endif
      EXPECT_GT(w.queries_per_frame, 0.0) << run.algorithm;
      EXPECT_GT(w.gl.queries, 0u) << run.algorithm;  // the pool served those queries
      EXPECT_LE(w.gl.queries_free, w.gl.queries) << run.algorithm;
      EXPECT_EQ(w.gl.buffers, 7u) << run.algorithm;
      EXPECT_GT(w.gl.buffer_bytes, 0) << run.algorithm;
    }
  }
  std::ostringstream text, json;
  print_soak(r, text);
  EXPECT_EQ(live.str(), text.str()) << "the table printed as it ran is the table of the result";
  EXPECT_NE(text.str().find("verdict:"), std::string::npos) << text.str();
  write_soak_json(r, json);
  const auto doc = nlohmann::json::parse(json.str());
  EXPECT_EQ(doc["format"], "occull soak 1");
  EXPECT_EQ(doc["runs"].size(), 3u);
  EXPECT_EQ(doc["runs"][0]["windows"][0]["gl_buffers"], 7);
  EXPECT_EQ(doc["runs"][0]["windows"][0]["heap_held_bytes"].get<std::uint64_t>(),
            r.runs[0].windows[0].heap_held_bytes);
}

TEST(Soak, MemoryThatKeepsGrowingIsALeakAndAHighWaterMarkIsNot) {
  SoakRun run;
  run.windows = {window(100 << 20, 50), window(104 << 20, 50)};
  judge_soak_run(run, 0.05);
  EXPECT_EQ(run.memory, SoakTrend::flat);
  run.windows.push_back(window(106 << 20, 50));  // past 5 %, rising in every step
  judge_soak_run(run, 0.05);
  EXPECT_EQ(run.memory, SoakTrend::growing);
  EXPECT_FALSE(run.leak_free());
  EXPECT_EQ(run.pool, SoakTrend::flat);
  run.windows.push_back(window(106 << 20, 50));  // and then it stops
  judge_soak_run(run, 0.05);
  EXPECT_EQ(run.memory, SoakTrend::plateau);
  EXPECT_TRUE(run.leak_free());
}

// The issue-45 case: chcpp's pool rose 52 -> 56 once, every query back in
// the pool at every window's end: a high-water mark, not a leak.
TEST(Soak, AQueryPoolThatRoseOnceIsAHighWaterMark) {
  SoakRun run;
  for (std::size_t q : {52, 52, 56, 56, 56}) run.windows.push_back(window(100 << 20, q));
  judge_soak_run(run, 0.05);
  EXPECT_EQ(run.pool, SoakTrend::plateau);
  EXPECT_EQ(run.in_use, SoakTrend::flat);
  EXPECT_TRUE(run.leak_free());
}

TEST(Soak, AQueryPoolThatGrowsEveryWindowIsALeak) {
  SoakRun run;
  for (std::size_t q : {118, 180, 240, 300}) run.windows.push_back(window(100 << 20, q));
  judge_soak_run(run, 0.05);
  EXPECT_EQ(run.pool, SoakTrend::growing);
  EXPECT_FALSE(run.leak_free());
}

TEST(Soak, QueriesHeldAtWindowEndsThatKeepGrowingAreALeak) {
  SoakRun run;
  for (std::size_t held : {0, 10, 20, 30}) run.windows.push_back(window(100 << 20, 400, held));
  judge_soak_run(run, 0.05);
  EXPECT_EQ(run.pool, SoakTrend::flat);
  EXPECT_EQ(run.in_use, SoakTrend::growing);
  EXPECT_FALSE(run.leak_free());
}

TEST(Soak, TrendsOfFiguresNotGivenAreFlat) {
  EXPECT_EQ(soak_trend(std::vector<double>{}, 0.05), SoakTrend::flat);
  EXPECT_EQ(soak_trend(std::vector<double>{5.0}, 0.05), SoakTrend::flat);
  EXPECT_EQ(soak_trend(std::vector<double>{0.0, 0.0, 0.0}, 0.05), SoakTrend::flat);
}

TEST(Soak, FramesThatAreNotAWholeNumberOfWindowsAreRejected) {
  SoakConfig c = tiny();
  c.frames = 30;
  EXPECT_THROW((void)run_soak(c), InputError);
  c.frames = 40;
  c.fps = 0.0;
  EXPECT_THROW((void)run_soak(c), InputError);
}
