// Runs the occull tool and checks exit codes and messages.
#include "require_data.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <stb_image.h>

#include <array>
#include <filesystem>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include <sys/wait.h>

namespace {

struct CliRun {
  int code = -1;
  std::string output;  // stdout and stderr
};

// `env` is prepended to the command line (e.g. "VAR=value").
CliRun run(const std::string& args, const std::string& env = "") {
  const std::string cmd = env + " " + std::string(OCCULL_CLI) + " " + args + " 2>&1";
  CliRun r;
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  std::array<char, 4096> buf{};
  while (std::fgets(buf.data(), int(buf.size()), pipe)) r.output += buf.data();
  const int status = pclose(pipe);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

constexpr const char* kTinyCity = "--scene city:blocks=3,traffic=3 --size 64x48";

// The cells of the table row of `algorithm` (split at spaces); empty if none.
std::vector<std::string> table_row(const std::string& output, const std::string& algorithm) {
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    std::istringstream cells(line);
    std::vector<std::string> row;
    for (std::string c; cells >> c;) row.push_back(c);
    if (!row.empty() && row[0] == algorithm) return row;
  }
  return {};
}

// Columns of the bench table (after the name).
enum Column { kMean = 1, kMedian, kP95, kMax, kVsVfc, kVsOracle, kQueries, kStates, kDraws, kTriangles,
              kMissed, kWrongPixels };

}  // namespace

TEST(Cli, HelpOnEveryCommandNamesItsOptions) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> commands = {
      {"", {"bench", "sweep", "calibrate", "render", "scenes", "algos", "info", "path", "traverse", "raster", "soak",
            "Exit codes"}},
      {"info", {"--help"}},
      {"scenes", {"--list-maps"}},
      {"algos", {"--help"}},
      {"path", {"--scene", "--path", "--out"}},
      {"bench", {"--scene", "--path", "--algo", "--frames", "--fps", "--start", "--size", "--query-mode",
                 "--query-raster", "--query-margin", "--draw", "--verify", "--repeat", "--model", "--json",
                 "--suite", "--malloc", "--views", "--gl-debug", "--stall-guard", "--watchdog"}},
      {"calibrate", {"--size", "--repeats", "--out", "--check"}},
      {"sweep", {"--algo", "--vary", "--baseline", "--popping", "--longest", "--scene", "--frames", "--json"}},
      {"render", {"--scene", "--frame", "--fps", "--out", "--png", "--view", "overview", "soc:", "--gl-debug"}},
      {"traverse", {"--dims", "--views", "--mode", "--fov", "--seed"}},
      {"raster", {"--scene", "--path", "--sizes", "--frames", "--repeat"}},
      {"soak", {"--scene", "--path", "--algo", "--frames", "--window", "--warmup", "--fps", "--size", "--json",
                "--gl-debug", "--stall-guard", "--watchdog"}}};
  for (const auto& [cmd, options] : commands) {
    const CliRun r = run(cmd + " --help");
    EXPECT_EQ(r.code, 0) << cmd << ": " << r.output;
    for (const std::string& o : options) EXPECT_NE(r.output.find(o), std::string::npos) << cmd << " help lacks " << o;
  }
}

TEST(Cli, NoCommandIsAUsageErrorThatSaysSo) {
  const CliRun r = run("");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("subcommand"), std::string::npos) << r.output;
}

TEST(Cli, UnknownCommandIsAUsageErrorThatNamesIt) {
  const CliRun r = run("frobnicate");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("unknown command 'frobnicate'; valid commands: info, scenes, path, algos, bench, sweep, "
                          "calibrate, render"),
            std::string::npos)
      << r.output;
}

TEST(Cli, UnknownSceneListsValidScenes) {
  const CliRun r = run("bench --scene town --frames 1");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("city, field"), std::string::npos) << r.output;
}

TEST(Cli, UnknownPathListsValidPaths) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --path nowhere --frames 1 --algo vfc --no-report");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("street, flyover, turn"), std::string::npos) << r.output;
}

TEST(Cli, UnknownAlgorithmListsValidAlgorithms) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc,magic --frames 1 --no-report");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("none, vfc"), std::string::npos) << r.output;
}

TEST(Cli, InvalidSizeIsRejected) {
  for (const char* size : {"0x10", "12", "axb", "20000x10", "64x48x2"}) {
    const CliRun r = run(std::string("bench --scene city:blocks=3 --algo vfc --frames 1 --size ") + size);
    EXPECT_EQ(r.code, 2) << size << ": " << r.output;
    EXPECT_NE(r.output.find("--size"), std::string::npos) << r.output;
  }
}

TEST(Cli, InvalidFrameCountIsRejected) {
  CliRun r = run(std::string("bench ") + kTinyCity + " --frames 0");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--frames 0: must be at least 1"), std::string::npos) << r.output;
  r = run(std::string("bench ") + kTinyCity + " --frames many");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--frames"), std::string::npos) << r.output;
  r = run(std::string("render ") + kTinyCity + " --frame 7 --frames 5 --out /dev/null");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--frame 7 is outside [0, 4]"), std::string::npos) << r.output;
}

TEST(Cli, UnknownOptionListsValidOptions) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc --frames 1 --opt vfc.speed=3 --no-report");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("valid options"), std::string::npos) << r.output;
}

TEST(Cli, OracleOfAnUnknownSetListsTheValidOnes) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo oracle:set=objects --frames 1 --no-report");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("'objects' is not one of pixels, boxes"), std::string::npos) << r.output;
}

TEST(Cli, InfoNamesTheRenderer) {
  const CliRun r = run("info");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("renderer"), std::string::npos);
  EXPECT_NE(r.output.find("GL_SAMPLES_PASSED"), std::string::npos);
}

TEST(Cli, ScenesListsParametersPathsAndCounts) {
  const CliRun r = run("scenes");
  EXPECT_EQ(r.code, 0);
  for (const char* s : {"city", "field", "blocks", "street", "flyover", "turn", "overview", "glide", "triangles"})
    EXPECT_NE(r.output.find(s), std::string::npos) << s;
}

TEST(Cli, BenchOnATiledWorldRunsItsAlgorithmsAgainstTilevfc) {
  // No --algo: the tiled-world set, each row against tilevfc.
  const CliRun r = run("bench --scene tiles_forest:far=120 --path walk10k --fps 30 --size 64x36 --frames 3 "
                       "--warmup 1 --no-report");
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* row : {"none", "tilevfc", "pertile", "tiles", "tiles:local=none", "oracle"})
    EXPECT_FALSE(table_row(r.output, row).empty()) << row << r.output;
  EXPECT_TRUE(table_row(r.output, "vfc").empty());
  ASSERT_GT(table_row(r.output, "tilevfc").size(), std::size_t(kVsVfc));
  EXPECT_EQ(table_row(r.output, "tilevfc")[kVsVfc], "1.00");
  for (const char* text : {"tiled world: 6 tiles in 64 m cells", "t.query", "postponed", "ms/tile",
                           "verification passed"})
    EXPECT_NE(r.output.find(text), std::string::npos) << text << r.output;
}

TEST(Cli, TiledWorldRefusesOtherAlgorithmsAndTooWideViews) {
  const CliRun vfc = run("bench --scene tiles_city:far=120 --size 64x36 --frames 1 --algo vfc --no-report");
  EXPECT_EQ(vfc.code, 2) << vfc.output;
  EXPECT_NE(vfc.output.find("vfc does not run on a tiled world"), std::string::npos) << vfc.output;
  EXPECT_NE(vfc.output.find("tilevfc, pertile, tiles"), std::string::npos) << vfc.output;
  const CliRun tiles = run(std::string("bench ") + kTinyCity + " --frames 1 --algo tiles --no-report");
  EXPECT_EQ(tiles.code, 2) << tiles.output;
  EXPECT_NE(tiles.output.find("tiles does not run on a scene that is not a tiled world"), std::string::npos)
      << tiles.output;
  const CliRun wide = run("bench --scene tiles_city:far=120 --size 96x36 --frames 1 --algo tiles --no-report");
  EXPECT_EQ(wide.code, 2) << wide.output;
  EXPECT_NE(wide.output.find("wider than 2:1"), std::string::npos) << wide.output;
}

TEST(Cli, BenchPrintsATableRowPerAlgorithm) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo none,vfc,oracle --frames 3 --warmup 1 --no-report");
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* row : {"\nnone ", "\nvfc ", "\noracle "})
    EXPECT_NE(r.output.find(row), std::string::npos) << row << r.output;
  for (const char* col : {"median", "vs vfc", "vs orcl", "missed", "wrong px"})
    EXPECT_NE(r.output.find(col), std::string::npos) << col;
}

TEST(Cli, RenderWritesAPngAndSaysWhatItDrew) {
  const std::string out = ::testing::TempDir() + "occull_cli_render.png";
  std::remove(out.c_str());
  const CliRun r = run(std::string("render ") + kTinyCity + " --frame 2 --frames 5 --out " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("wrote " + out + " (64x48)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frame 2 with vfc"), std::string::npos) << r.output;
  std::ifstream f(out, std::ios::binary);
  char magic[8] = {};
  f.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
}

TEST(Cli, RenderDebugViewWritesANumberedSequenceAndItsLegend) {
  const std::string out = ::testing::TempDir() + "occull_cli_view.png";
  const auto numbered = [&](int k) { return ::testing::TempDir() + "occull_cli_view-000" + std::to_string(k) + ".png"; };
  for (int k = 1; k <= 4; ++k) std::remove(numbered(k).c_str());
  const CliRun r =
      run(std::string("render ") + kTinyCity + " --algo chc --view queries --frame 2-4 --frames 5 --png " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  for (int k = 2; k <= 4; ++k) {
    EXPECT_TRUE(std::filesystem::exists(numbered(k))) << numbered(k);
    EXPECT_NE(r.output.find("wrote " + numbered(k)), std::string::npos) << r.output;
  }
  EXPECT_FALSE(std::filesystem::exists(numbered(1)));
  EXPECT_NE(r.output.find("view queries"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("occluded"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("wasted"), std::string::npos) << r.output;
}

TEST(Cli, RenderShowsTheGridsCellsAndEndsCleanly) {
  // The grid culler holds its last frame's queries until render hands them
  // back (a crash once, when it read them through a logger gone by then).
  const CliRun r = run(std::string("render ") + kTinyCity + " --algo grid --view cells --frame 3 --frames 5 --out /dev/null");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("cells drawn"), std::string::npos) << r.output;
}

TEST(Cli, RenderTakesTheAlgorithmSpecsBenchTakes) {
  CliRun r = run(std::string("render ") + kTinyCity + " --algo chcpp:batch=20 --frame 2 --frames 3 --out /dev/null");
  EXPECT_EQ(r.code, 0) << r.output;
  r = run(std::string("render ") + kTinyCity + " --algo oracle --out /dev/null");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("ground truth"), std::string::npos) << r.output;
}

TEST(Cli, RenderShowsTheOcclusionBufferBesideTheFrame) {
  const std::string out = ::testing::TempDir() + "occull_cli_soc.png";
  std::remove(out.c_str());
  CliRun r = run(std::string("render ") + kTinyCity + " --algo soc:scale=4 --view soc --frame 2 --frames 5 --out " + out);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("(128x48)"), std::string::npos) << r.output;  // the frame and the buffer, side by side
  EXPECT_NE(r.output.find("the occlusion buffer, 16x12 texels"), std::string::npos) << r.output;
  EXPECT_TRUE(std::filesystem::exists(out));
  r = run(std::string("render ") + kTinyCity + " --algo chcpp:cpu_test=on --view soc --frame 2 --frames 5 --out /dev/null");
  EXPECT_EQ(r.code, 0) << r.output;
  r = run(std::string("render ") + kTinyCity + " --algo chcpp --view soc --out /dev/null");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("cpu_test=on"), std::string::npos) << r.output;
}

TEST(Cli, RasterTimesTheRasterizerAndRefusesABadSize) {
  CliRun r = run("raster --scene city:blocks=3 --frames 2 --repeat 1 --sizes 64x36,100x50");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("64x36"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("100x50"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("SIMD: "), std::string::npos) << r.output;
  r = run("raster --sizes 64by36");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("64by36"), std::string::npos) << r.output;
}

TEST(Cli, RenderRefusesAViewTheAlgorithmHasNot) {
  CliRun r = run(std::string("render ") + kTinyCity + " --algo chc --view cells --out /dev/null");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--algo grid"), std::string::npos) << r.output;
  r = run(std::string("render ") + kTinyCity + " --algo grid --view tiles --out /dev/null");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("tilevfc, pertile, tiles"), std::string::npos) << r.output;
  r = run(std::string("render ") + kTinyCity + " --view wireframe --out /dev/null");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("valid: color, queries"), std::string::npos) << r.output;
  r = run(std::string("render ") + kTinyCity + " --frame 3-1 --out /dev/null");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("ends before it starts"), std::string::npos) << r.output;
}

TEST(Cli, MissingEglDriverExitsThreeWithAnInstallHint) {
  // GLVND finds no EGL vendor library: as on a machine without Mesa's EGL.
  const CliRun r = run("info", "__EGL_VENDOR_LIBRARY_FILENAMES=/nonexistent/vendor.json");
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_NE(r.output.find("apt-get install"), std::string::npos) << r.output;
}

TEST(Cli, DriverWithoutOpenGL45ExitsThree) {
  if (run("info").output.find("Mesa") == std::string::npos) GTEST_SKIP() << "needs a Mesa driver";
  const CliRun r = run("info", "MESA_GL_VERSION_OVERRIDE=3.3");
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_NE(r.output.find("4.5"), std::string::npos) << r.output;
}

TEST(Cli, BenchWritesJsonCsvAndTheReportFolder) {
  const std::string dir = ::testing::TempDir() + "occull_cli_report";
  const std::string json = ::testing::TempDir() + "occull_cli.json";
  const std::string csv = ::testing::TempDir() + "occull_cli.csv";
  std::remove(json.c_str());
  std::remove(csv.c_str());
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc,oracle --frames 3 --warmup 0 --repeat 2 --json " +
                       json + " --csv " + csv + " --report " + dir);
  ASSERT_EQ(r.code, 0) << r.output;
  for (const std::string& f : {json, csv, dir + "/report.md", dir + "/frame_ms.svg", dir + "/queries.svg",
                               dir + "/triangles.svg"})
    EXPECT_TRUE(std::ifstream(f).good()) << f;
  std::ifstream in(json);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"repeat\": 2"), std::string::npos) << text.substr(0, 400);
}

TEST(Cli, OracleWithoutVerificationIsAUsageError) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo oracle --frames 2 --verify off --no-report");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("ground truth"), std::string::npos) << r.output;
}

TEST(Cli, InvalidRepeatAndVerifyValuesAreRejected) {
  CliRun r = run(std::string("bench ") + kTinyCity + " --repeat 0 --no-report");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--repeat 0: must be at least 1"), std::string::npos) << r.output;
  r = run(std::string("bench ") + kTinyCity + " --verify maybe --no-report");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("--verify 'maybe': expected on or off"), std::string::npos) << r.output;
}

TEST(Cli, UnwritableReportFolderIsAClearError) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc --frames 1 --warmup 0 --report /proc/occull-report");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("/proc/occull-report"), std::string::npos) << r.output;
}

TEST(Cli, CalibrateWritesAProfileThatNohcLoads) {
  const std::string profile = ::testing::TempDir() + "occull_profile.json";
  std::remove(profile.c_str());
  const CliRun cal = run("calibrate --size 160x90 --repeats 1 --out " + profile);
  ASSERT_EQ(cal.code, 0) << cal.output;
  for (const char* q : {"T_r^s", "T_r^tri", "T_r^f[0]", "T_o^s", "T_o^f", "T_o^l", "T_o^o", " ms", "ns"})
    EXPECT_NE(cal.output.find(q), std::string::npos) << q;
  const CliRun bench = run(std::string("bench ") + kTinyCity + " --algo nohc --frames 2 --warmup 0 --no-report --opt nohc.profile=" + profile);
  EXPECT_EQ(bench.code, 0) << bench.output;
  EXPECT_FALSE(table_row(bench.output, "nohc").empty()) << bench.output;
  EXPECT_EQ(bench.output.find("calibrating"), std::string::npos) << "the given profile is used";
}

TEST(Cli, CalibrateCheckReportsVerdictsAndWritesNothing) {
  const std::string cache = ::testing::TempDir() + "occull_check_cache";
  std::filesystem::remove_all(cache);
  const CliRun r = run("calibrate --check --size 96x54 --repeats 1", "XDG_CACHE_HOME=" + cache);
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* s : {"first run:", "second run:", "a triangle costs less than a draw call", "repeats within a factor of 2",
                        "checks suspect"})
    EXPECT_NE(r.output.find(s), std::string::npos) << s << "\n" << r.output;
  EXPECT_FALSE(std::filesystem::exists(cache + "/occull")) << "--check writes no profile";
}

TEST(Cli, ModelPrintsPredictedAgainstMeasuredForEveryAlgorithm) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc,chcpp --frames 3 --warmup 0 --model --no-report --opt nohc.profile=" +
                       OCCULL_TEST_PROFILE);
  ASSERT_EQ(r.code, 0) << r.output;
  const auto at = r.output.find("cost model (NOHC");
  ASSERT_NE(at, std::string::npos) << r.output;
  const std::string model = r.output.substr(at);
  EXPECT_NE(model.find("predicted"), std::string::npos);
  for (const char* algo : {"vfc", "chcpp"}) {
    const auto row = table_row(model, algo);
    ASSERT_EQ(row.size(), 4u) << algo << "\n" << model;  // name, measured, predicted, error
    EXPECT_GT(std::stod(row[2]), 0.0) << "a frame that draws is predicted to cost time";
  }
}

TEST(Cli, EveryQueryModeRunsVerifiedWithoutMisses) {
  for (const char* mode : {"samples", "any", "conservative"}) {
    const CliRun r = run(std::string("bench ") + kTinyCity + " --algo chc,chcpp --frames 4 --warmup 0 --no-report --query-mode " + mode);
    ASSERT_EQ(r.code, 0) << mode << "\n" << r.output;
    EXPECT_NE(r.output.find("verification passed"), std::string::npos) << mode << "\n" << r.output;
    for (const char* algo : {"chc", "chcpp"}) {
      const auto row = table_row(r.output, algo);
      ASSERT_GT(row.size(), std::size_t(kMissed)) << r.output;
      EXPECT_GT(std::stod(row[kQueries]), 0.0) << mode << " " << algo;
    }
  }
  EXPECT_EQ(run(std::string("bench ") + kTinyCity + " --query-mode some --no-report").code, 2);
}

TEST(Cli, EveryDrawModeSubmitsTheSameObjects) {
  std::vector<std::string> rows[3];
  int i = 0;
  for (const char* draw : {"single", "multi", "indirect"}) {
    const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc,oracle --frames 4 --warmup 0 --no-report --draw " + draw);
    ASSERT_EQ(r.code, 0) << draw << "\n" << r.output;
    rows[i++] = table_row(r.output, "vfc");
  }
  for (int k = 0; k < 3; ++k) ASSERT_GT(rows[k].size(), std::size_t(kTriangles));
  for (int k : {1, 2}) {
    EXPECT_EQ(rows[0][kDraws], rows[k][kDraws]);
    EXPECT_EQ(rows[0][kTriangles], rows[k][kTriangles]);
  }
  const CliRun bad = run(std::string("bench ") + kTinyCity + " --draw batched --no-report");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.output.find("valid modes: single, multi, indirect"), std::string::npos) << bad.output;
}

// hiz runs from the command line, verified, beside vfc, with its device
// times in the JSON.
TEST(Cli, HizRunsVerifiedWithItsDeviceTimes) {
  const std::string json = ::testing::TempDir() + "occull_cli_hiz.json";
  std::remove(json.c_str());
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc,hiz --frames 4 --warmup 1 --no-report --json " + json);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("missed no visible object"), std::string::npos) << r.output;
  std::ifstream in(json);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"pyramid_ms_per_frame\""), std::string::npos);
  EXPECT_NE(text.find("\"device_cull_ms_per_frame\""), std::string::npos);
}

TEST(Cli, QueryGeometryIsReportedAndSelectable) {
  const CliRun info = run("info");
  EXPECT_NE(info.output.find("query boxes are kept conservative by: outline widened by 0.125 px"), std::string::npos)
      << info.output;
  const CliRun exact = run(std::string("bench ") + kTinyCity + " --algo vfc --frames 2 --warmup 0 --no-report --query-raster exact");
  ASSERT_EQ(exact.code, 0) << exact.output;
  EXPECT_NE(exact.output.find("query boxes: exact boxes"), std::string::npos) << exact.output;
  const CliRun hardware = run(std::string("bench ") + kTinyCity + " --algo vfc --frames 2 --warmup 0 --no-report --query-raster hardware");
  ASSERT_EQ(hardware.code, 0) << hardware.output;
  EXPECT_NE(hardware.output.find("query boxes: "), std::string::npos) << hardware.output;
  const CliRun bad = run(std::string("bench ") + kTinyCity + " --query-raster fuzzy --no-report");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.output.find("valid values: margin, hardware, exact"), std::string::npos) << bad.output;
  EXPECT_EQ(run(std::string("bench ") + kTinyCity + " --query-margin -1 --no-report").code, 2);
}

TEST(Cli, CorruptProfileIsAClearError) {
  const std::string profile = ::testing::TempDir() + "occull_bad_profile.json";
  std::ofstream(profile) << "{\"renderer\": \"x\", \"size\": [1, 1]}";
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo nohc --frames 1 --no-report --opt nohc.profile=" + profile);
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(profile), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("draw_setup_ms"), std::string::npos) << r.output;
}

TEST(Cli, ListMapsOfAnArchive) {
  const std::string pk3 = std::string(OCCULL_DATA_DIR) + "/openarena/pak1-maps.pk3";
  OCCULL_REQUIRE_DATA(pk3);
  const CliRun r = run("scenes --list-maps " + pk3);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("50 maps"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("oasago2"), std::string::npos);
}

TEST(Cli, BadLevelFilesExitTwoNamingTheFile) {
  const std::string junk = ::testing::TempDir() + "occull_junk.pk3";
  std::ofstream(junk) << "junk";
  CliRun r = run("bench --scene q3:" + junk + ":x --frames 1 --no-report");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("not a zip"), std::string::npos) << r.output;
  const std::string bsp = ::testing::TempDir() + "occull_junk.bsp";
  std::ofstream(bsp) << "IBSP";
  r = run("render --scene q3:" + bsp + " --out /dev/null");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("truncated"), std::string::npos) << r.output;
  r = run("bench --scene file:/nonexistent/model.gltf --frames 1 --no-report");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("no such file"), std::string::npos) << r.output;
}

TEST(Cli, WrittenPathReplaysThroughFilePaths) {
  const std::string file = ::testing::TempDir() + "occull_street.path";
  const CliRun w = run(std::string("path --scene city:blocks=3 --path street --out ") + file);
  ASSERT_EQ(w.code, 0) << w.output;
  const CliRun r = run(std::string("bench ") + kTinyCity + " --path file:" + file + " --algo vfc --frames 3 --warmup 0 --no-report");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("path file:occull_street.path"), std::string::npos) << r.output;
}

TEST(Cli, ModelFilesLoadThroughAssimp) {
  // A cube written as Wavefront OBJ.
  const std::string obj = ::testing::TempDir() + "occull_cube.obj";
  std::ofstream(obj) << "v -1 -1 -1\nv 1 -1 -1\nv 1 1 -1\nv -1 1 -1\nv -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\n"
                        "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 4 8 7\nf 4 7 3\nf 1 5 8\nf 1 8 4\n"
                        "f 2 3 7\nf 2 7 6\n";
  const CliRun r = run("bench --scene file:" + obj + " --algo vfc,chcpp,oracle --frames 4 --warmup 0 --size 96x54 --no-report");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("12 triangles"), std::string::npos) << r.output;
  const auto oracle = table_row(r.output, "oracle");
  ASSERT_GT(oracle.size(), std::size_t(kTriangles)) << r.output;
  EXPECT_EQ(oracle[kTriangles], "12") << "the cube is in view and drawn";
}

// Found by fuzz_model: an OFF file whose face names vertices it lacks made
// assimp assert and abort the process (exit 134).
TEST(Cli, AModelFileWithFacesWithoutVerticesExitsTwoNamingIt) {
  const std::string off = ::testing::TempDir() + "occull_broken.off";
  std::ofstream(off) << "OFF\n3 1 0\n0 0 0 1 2\n";
  const CliRun r = run("bench --scene file:" + off + " --algo vfc --frames 1 --no-report");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find(off + ": cannot be read as a model"), std::string::npos) << r.output;
}

// The newcomer's first run: no hardware profile cached, so nohc calibrates
// in the bench's own process — which once left the ground truth empty and
// the oracle drawing nothing, with every culler "missing 0".
TEST(Cli, FirstRunWithAnEmptyCacheCalibratesAndTheOracleDraws) {
  const std::string cache = ::testing::TempDir() + "occull_empty_cache";
  std::filesystem::remove_all(cache);
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc,nohc,oracle --frames 3 --warmup 1 --no-report",
                       "XDG_CACHE_HOME=" + cache);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("calibrating"), std::string::npos) << r.output;
  const auto oracle = table_row(r.output, "oracle");
  ASSERT_GT(oracle.size(), std::size_t(kTriangles)) << r.output;
  EXPECT_GT(std::stod(oracle[kDraws]), 0.0) << r.output;
  EXPECT_GT(std::stod(oracle[kTriangles]), 0.0) << r.output;
  EXPECT_EQ(oracle[kMissed], "0");
  const auto vfc = table_row(r.output, "vfc");
  ASSERT_GT(vfc.size(), std::size_t(kDraws));
  EXPECT_GE(std::stod(vfc[kDraws]), std::stod(oracle[kDraws])) << "the oracle draws a subset of vfc";
  std::size_t profiles = 0;
  for (const auto& e : std::filesystem::directory_iterator(cache + "/occull"))
    profiles += e.path().extension() == ".json" ? 1 : 0;
  EXPECT_EQ(profiles, 1u) << "the calibrated profile is cached";
}

TEST(Cli, FpsPlacesFramesAtARealTimeRateAndSaysHowFarTheCameraMoves) {
  const CliRun spread = run(std::string("bench ") + kTinyCity + " --algo vfc --frames 4 --warmup 0 --no-report");
  ASSERT_EQ(spread.code, 0) << spread.output;
  EXPECT_NE(spread.output.find("frames spread over the whole path"), std::string::npos) << spread.output;
  const CliRun fps = run(std::string("bench ") + kTinyCity +
                         " --algo vfc --frames 4 --warmup 0 --fps 60 --start 2 --no-report");
  ASSERT_EQ(fps.code, 0) << fps.output;
  EXPECT_NE(fps.output.find("frames at 60 fps from 2.0 s of the path"), std::string::npos) << fps.output;
  // "the camera moves X m": far less at 60 fps than with 4 frames over the path.
  const auto step = [](const std::string& out) {
    const auto at = out.find("the camera moves ");
    return at == std::string::npos ? -1.0 : std::stod(out.substr(at + 17));
  };
  EXPECT_GT(step(spread.output), 0.0);
  EXPECT_GE(step(fps.output), 0.0);
  EXPECT_LT(step(fps.output), step(spread.output) / 10.0);
}

TEST(Cli, FramesPastTheEndOfThePathAreRejected) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc --frames 5000 --fps 60 --start 1 --no-report");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("runs past the end of path street"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("frames fit"), std::string::npos) << r.output;
  EXPECT_EQ(run(std::string("bench ") + kTinyCity + " --algo vfc --fps -3 --no-report").code, 2);
  EXPECT_EQ(run(std::string("render ") + kTinyCity + " --fps 60 --start 1000 --out /dev/null").code, 2);
}

TEST(Cli, BenchNamesTheAllocatorPolicyAndSaysWhereTheTimeGoes) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --frames 2 --warmup 0 --algo vfc,chcpp --no-report");
  ASSERT_EQ(r.code, 0) << r.output;
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer replaces malloc: mallopt refuses, and the tool says so.
  EXPECT_NE(r.output.find("allocator: system (glibc refused"), std::string::npos) << r.output;
#else
  EXPECT_NE(r.output.find("allocator: engine"), std::string::npos) << r.output;
#endif
  EXPECT_NE(r.output.find("where the time goes"), std::string::npos) << r.output;
  for (const char* column : {"cpu ms", "us/node", "faults", "sys ms"})
    EXPECT_NE(r.output.find(column), std::string::npos) << column;
  const CliRun system = run(std::string("bench ") + kTinyCity + " --frames 1 --warmup 0 --algo vfc --no-report --malloc system");
  ASSERT_EQ(system.code, 0) << system.output;
  EXPECT_NE(system.output.find("allocator: system"), std::string::npos) << system.output;
  const CliRun bad = run(std::string("bench ") + kTinyCity + " --frames 1 --algo vfc --no-report --malloc tcmalloc");
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_NE(bad.output.find("engine, system"), std::string::npos) << bad.output;
}

TEST(Cli, QuickSuiteRunsEveryEntryAndSummarisesEachCuller) {
  const std::string dir = std::filesystem::temp_directory_path() / "occull-cli-suite";
  std::filesystem::remove_all(dir);
  const CliRun r = run("bench --suite quick --algo vfc,chcpp,oracle --frames 2 --warmup 0 --size 64x48 --report " +
                       dir + " --json " + dir + ".json");
  ASSERT_EQ(r.code, 0) << r.output;
  for (const char* entry : {"== 1. city", "== 2. field", "== 3. track"})
    EXPECT_NE(r.output.find(entry), std::string::npos) << entry;
  EXPECT_NE(r.output.find("suite quick — 3 of 3 entries ran"), std::string::npos) << r.output;
  const std::vector<std::string> chcpp = table_row(r.output.substr(r.output.find("geomean/vfc")), "chcpp");
  ASSERT_GE(chcpp.size(), 3u) << r.output;
  EXPECT_EQ(chcpp[1], "3") << "chcpp ran in every entry";
  std::ifstream in(dir + ".json");
  const nlohmann::json doc = nlohmann::json::parse(in);
  EXPECT_EQ(doc["suite"], "quick");
  ASSERT_EQ(doc["runs"].size(), 3u);
  ASSERT_EQ(doc["summary"].size(), 3u);
  // vfc's ratio to itself is 1 in every entry, so its geometric mean is too.
  EXPECT_DOUBLE_EQ(doc["summary"][0]["geomean_to_vfc"].get<double>(), 1.0);
  EXPECT_EQ(doc["summary"][2]["algorithm"], "oracle");
  for (const char* file : {"suite.md", "suite.json", "ratio_to_vfc.svg", "ratio_to_oracle.svg"})
    EXPECT_TRUE(std::filesystem::exists(std::filesystem::path(dir) / file)) << file;
  std::filesystem::remove_all(dir);
  std::filesystem::remove(dir + ".json");
}

TEST(Cli, UnknownSuiteListsTheValidOnesAndASuiteExcludesAScene) {
  const CliRun unknown = run("bench --suite nightly --frames 1");
  EXPECT_EQ(unknown.code, 2) << unknown.output;
  EXPECT_NE(unknown.output.find("valid suites: default, quick"), std::string::npos) << unknown.output;
  const CliRun both = run("bench --suite quick --scene field --frames 1");
  EXPECT_EQ(both.code, 2) << both.output;
  EXPECT_NE(both.output.find("excludes"), std::string::npos) << both.output;
}

TEST(Cli, SweepRunsEverySettingBesideTheBaselineAndNamesTheBest) {
  const CliRun r = run(std::string("sweep ") + kTinyCity +
                       " --algo grid --vary cap=1,4000 --vary vis_duration=2,20 --frames 3 --warmup 1");
  ASSERT_EQ(r.code, 0) << r.output;
  // A row per setting: the swept values first, then the figures.
  for (const char* cap : {"1", "4000"}) {
    int rows = 0;
    std::istringstream lines(r.output);
    for (std::string line; std::getline(lines, line);)
      rows += line.rfind(std::string(cap) + " ", 0) == 0 && line.find("%") != std::string::npos ? 1 : 0;
    EXPECT_EQ(rows, 2) << "cap " << cap << ": " << r.output;
  }
  EXPECT_NE(r.output.find("beside it: vfc"), std::string::npos) << r.output;
  const bool verdict = r.output.find("\nbest: grid:") != std::string::npos ||
                       r.output.find("\nno setting misses at most 0.10%") != std::string::npos;
  EXPECT_TRUE(verdict) << r.output;
}

TEST(Cli, SweepOfAnUnknownOptionListsTheValidOnes) {
  const CliRun r = run("sweep --vary capp=1,2");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("valid options: cell, traversal, cap"), std::string::npos) << r.output;
  const CliRun two = run("sweep --algo grid,vfc --vary cap=1");
  EXPECT_EQ(two.code, 2) << two.output;
}

TEST(Cli, StallGuardKeepsConservativeCullersConservativeAndRejectsNegativeTimes) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc,chcpp,stopwait --frames 4 --warmup 1 "
                       "--stall-guard 0.001");
  EXPECT_EQ(r.code, 0) << r.output;  // 4 would mean a conservative culler missed an object
  EXPECT_NE(r.output.find("verification passed"), std::string::npos) << r.output;
  EXPECT_EQ(run("bench --stall-guard -1 --frames 1").code, 2);
}

// A frame past the watchdog's time stops the run with exit 1 and names the
// frame (a microsecond: no GL frame with glFinish is that fast).
TEST(Cli, AFramePastTheWatchdogsTimeStopsTheRunNamingIt) {
  const CliRun r = run(std::string("bench ") + kTinyCity + " --algo vfc --frames 2 --warmup 0 --watchdog 0.000001");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("occull: watchdog: ground-truth frame 0 of path street has not finished"), std::string::npos)
      << r.output;
  EXPECT_EQ(run("bench --watchdog -5 --frames 1").code, 2);
}

TEST(Cli, TraverseTimesTheGridTraversalAndRejectsBadDimensions) {
  const CliRun r = run("traverse --dims 30x4x20 --views 5");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("grid 30x4x20 (2400 cells), 5 views"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("traversal per view: median"), std::string::npos) << r.output;
  for (const char* bad : {"--dims 30x4", "--dims 0x4x20", "--mode cone", "--views 0"}) {
    const CliRun e = run(std::string("traverse ") + bad);
    EXPECT_EQ(e.code, 2) << bad << ": " << e.output;
  }
  EXPECT_NE(run("traverse --mode cone").output.find("valid modes are frustum, box"), std::string::npos);
}

TEST(Cli, SplitScreenBenchNamesBothPathsAndAPathListNeedsViews) {
  const CliRun r = run("bench --scene city:blocks=3,traffic=3 --size 128x48 --views 2 --path street,turn "
                       "--algo vfc,grid --frames 2 --warmup 0 --no-report");
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("path street | turn"), std::string::npos) << r.output;
  EXPECT_FALSE(table_row(r.output, "grid").empty()) << r.output;
  EXPECT_NE(r.output.find("\ngrid [view 2] "), std::string::npos) << r.output;
  const CliRun list = run("bench --path street,turn --frames 1");
  EXPECT_EQ(list.code, 2) << list.output;
  EXPECT_NE(list.output.find("needs --views"), std::string::npos) << list.output;
}

TEST(Cli, SoakPrintsAWindowRowPerAlgorithmAndAVerdictAndRejectsAPartialWindow) {
  const std::string json = ::testing::TempDir() + "occull_soak.json";
  const CliRun r = run(std::string("soak ") + kTinyCity + " --algo chcpp --frames 20 --window 10 --warmup 2 --json " + json);
  EXPECT_TRUE(r.code == 0 || r.code == 5) << r.output;  // 5: memory or the pool grew (exit code documented)
  EXPECT_NE(r.output.find("chcpp: memory"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("verdict: "), std::string::npos) << r.output;
  // The soak judges resident memory, which glibc's defaults let shrink.
  EXPECT_NE(r.output.find("allocator: system"), std::string::npos) << r.output;
  std::ifstream in(json);
  EXPECT_EQ(nlohmann::json::parse(in)["flat"].get<bool>(), r.code == 0);
  const CliRun bad = run(std::string("soak ") + kTinyCity + " --frames 25 --window 10");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.output.find("must be a positive multiple of the window"), std::string::npos) << bad.output;
}

TEST(Cli, TheExitCodesOfTheReadmeAreTheOnesTheHelpAndTheToolUse) {
  // The README's table and --help must list the same codes, 0 to 5, in the same words.
  std::ifstream readme(std::string(OCCULL_SOURCE_DIR) + "/README.md");
  std::string line;
  while (std::getline(readme, line) && line != "## Exit codes") {}
  std::vector<int> documented;
  const CliRun help = run("--help");
  while (std::getline(readme, line) && line.rfind("## ", 0) != 0)
    if (line.size() > 6 && line[0] == '|' && std::isdigit(static_cast<unsigned char>(line[2]))) {
      documented.push_back(line[2] - '0');
      const std::string meaning = line.substr(6, line.size() - 6 - 2);  // "| N | meaning |"
      EXPECT_NE(help.output.find(std::string("  ") + line[2] + "  " + meaning + "\n"), std::string::npos)
          << "--help does not say, as the README does: " << line << "\n" << help.output;
    }
  EXPECT_EQ(documented, (std::vector<int>{0, 1, 2, 3, 4, 5}));
  // And the tool uses them: 0, 2 here; 1 (watchdog), 3 (no EGL driver),
  // 5 (soak) in their own tests; 4 is verification_failures() of a run
  // (Verdict.MissesOfConservativeRunsFailThoseOfOthersArePopping).
  EXPECT_EQ(run("algos").code, 0);
  EXPECT_EQ(run("bench --scene nope").code, 2);
}

// occull view under a virtual X server (xvfb-run, installed by make test's set-up).
namespace {

std::vector<std::uint8_t> read_png(const std::string& file, int& w, int& h) {
  int n = 0;
  unsigned char* p = stbi_load(file.c_str(), &w, &h, &n, 4);
  if (!p) return {};
  std::vector<std::uint8_t> rgba(p, p + std::size_t(w) * std::size_t(h) * 4);
  stbi_image_free(p);
  return rgba;
}

CliRun run_viewer(const std::string& args) {
  return run("view " + args, "xvfb-run -a -s '-screen 0 640x480x24'");
}

constexpr const char* kViewScene = "--scene city:blocks=3,traffic=3 --size 160x90";

}  // namespace

TEST(Viewer, ShowsTheQueriesViewOfAFrameAsRenderDrawsIt) {
  const std::string dir = ::testing::TempDir();
  const std::string shot = dir + "occull_view_queries.png", rendered = dir + "occull_render_queries.png";
  std::remove(shot.c_str());
  // stop-and-wait: no decision depends on when a result arrives, so both runs draw the same frame.
  CliRun r = run_viewer(std::string(kViewScene) +
                        " --algo stopwait --view queries --verify --frames 10 --fps 30 --no-ui --screenshot " + shot);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("flew 10 frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("missed 0 of"), std::string::npos) << r.output;
  r = run(std::string("render ") + kViewScene +
          " --algo stopwait --view queries --fps 30 --frame 9 --frames 10 --png " + rendered);
  ASSERT_EQ(r.code, 0) << r.output;
  int w = 0, h = 0, w2 = 0, h2 = 0;
  const auto a = read_png(shot, w, h), b = read_png(rendered, w2, h2);
  ASSERT_EQ(w, 160);
  ASSERT_EQ(h, 90);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(a == b) << "the viewer's window differs from render --view queries";
  // And it shows occluded queries: pixels in a shade of the occluded colour (0.85, 0.15, 0.15).
  std::size_t red = 0;
  for (std::size_t i = 0; i < a.size(); i += 4) red += a[i] > 100 && a[i] > 4 * a[i + 1] && a[i + 1] == a[i + 2];
  EXPECT_GT(red, 100u);
}

TEST(Viewer, WithItsPanelTheViewStillShowsAroundIt) {
  const std::string shot = ::testing::TempDir() + "occull_view_panel.png";
  const CliRun r = run_viewer("--scene city:blocks=3,traffic=3 --size 640x360 --algo grid --view cells --frames 3 "
                              "--screenshot " + shot);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("cells drawn"), std::string::npos) << r.output;
  int w = 0, h = 0;
  const auto a = read_png(shot, w, h);
  ASSERT_EQ(w, 640);
  // Green (drawn) cells right of the panel (250 px wide at x = 8).
  std::size_t green = 0;
  for (int y = 0; y < h; ++y)
    for (int x = 300; x < w; ++x) {
      const std::size_t i = (std::size_t(y) * std::size_t(w) + std::size_t(x)) * 4;
      green += a[i + 1] > 100 && a[i + 1] > 2 * a[i] && a[i + 1] > 2 * a[i + 2];
    }
  EXPECT_GT(green, 100u);
}

TEST(Viewer, RecordsTheFlightAsAPathBenchReplays) {
  const std::string file = ::testing::TempDir() + "occull_flight.path";
  std::remove(file.c_str());
  CliRun r = run_viewer(std::string(kViewScene) + " --frames 5 --no-ui --record " + file);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("wrote " + file + " (5 keys"), std::string::npos) << r.output;
  r = run(std::string("bench ") + kViewScene + " --algo vfc --frames 5 --path file:" + file);
  EXPECT_EQ(r.code, 0) << r.output;
}

TEST(Viewer, RefusesAViewItsAlgorithmHasNot) {
  const CliRun r = run_viewer(std::string(kViewScene) + " --algo chc --view cells --frames 1");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("cells: grid"), std::string::npos) << r.output;
}

#ifdef OCCULL_OSG
TEST(Cli, OsgRunsOsgsRowsBesideOccullsAndRefusesAnUnknownRowOrAnUnwritableExport) {
  const CliRun help = run("osg --help");
  EXPECT_EQ(help.code, 0);
  for (const char* o : {"--rows", "--threading", "--export", "oqn-strict", "--scene", "--frames", "--json", "--report"})
    EXPECT_NE(help.output.find(o), std::string::npos) << "osg help lacks " << o;
  const std::string png = ::testing::TempDir() + "occull_cli_osg";
  const CliRun r = run(std::string("osg ") + kTinyCity + " --rows osg,oqn,chcpp --frames 3 --warmup 1 --png " + png);
  EXPECT_EQ(r.code, 0) << r.output;
  for (const char* name : {"osg", "oqn", "chcpp"}) {
    const std::string file = png + "-" + name + ".png";
    EXPECT_NE(r.output.find("wrote " + file), std::string::npos) << r.output;
    EXPECT_GT(std::filesystem::exists(file) ? std::filesystem::file_size(file) : 0u, 100u) << file;
  }
  for (const char* name : {"osg", "oqn", "chcpp"}) EXPECT_FALSE(table_row(r.output, name).empty()) << name << r.output;
  EXPECT_NE(r.output.find("inside OpenSceneGraph"), std::string::npos) << r.output;
  const CliRun bad = run(std::string("osg ") + kTinyCity + " --rows osg,occlusionquery --frames 1");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.output.find("row occlusionquery: not osg, oqn or oqn-strict"), std::string::npos) << bad.output;
  const CliRun unwritable = run(std::string("osg ") + kTinyCity + " --export /nonexistent/folder/city.osgb");
  EXPECT_EQ(unwritable.code, 2);
  EXPECT_NE(unwritable.output.find("/nonexistent/folder/city.osgb: OpenSceneGraph cannot write it"), std::string::npos)
      << unwritable.output;
  const CliRun threading = run(std::string("osg ") + kTinyCity + " --threading draw --frames 1");
  EXPECT_EQ(threading.code, 2);
  EXPECT_NE(threading.output.find("supports SingleThreaded and CullDrawThreadPerContext"), std::string::npos)
      << threading.output;
}

TEST(Cli, OsgFlysAFileOsgReadsVerifiedAndRefusesOneItCannotRead) {
  const std::string file = ::testing::TempDir() + "occull_cli_city.osgt";
  const CliRun exported = run(std::string("osg ") + kTinyCity + " --export " + file);
  ASSERT_EQ(exported.code, 0) << exported.output;
  const CliRun r = run("osg --file " + file + " --rows osg,vfc,chcpp --frames 4 --warmup 1 --size 64x48");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("path orbit"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("verification passed"), std::string::npos) << r.output;
  const std::vector<std::string> chcpp = table_row(r.output, "chcpp");
  ASSERT_GT(chcpp.size(), std::size_t(kMissed)) << r.output;
  EXPECT_EQ(chcpp[kMissed], "0") << r.output;
  const CliRun missing = run("osg --file /nonexistent/model.osgb --frames 1");
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.output.find("/nonexistent/model.osgb: no such file"), std::string::npos) << missing.output;
  const std::string damaged = ::testing::TempDir() + "occull_cli_damaged.osgt";
  std::ofstream(damaged) << "#Ascii Scene\n#Version 161\nosg::Group {\n  UniqueID 1\n  Children 7 {\n";
  const CliRun bad = run("osg --file " + damaged + " --frames 1");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.output.find(damaged + ": "), std::string::npos) << bad.output;
}
#endif
