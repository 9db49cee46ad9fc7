// `occull osg`: occull's cullers inside OpenSceneGraph beside OSG's own
// OcclusionQueryNode, in one headless viewer, every frame verified.
#include "run_options.hpp"

#include "occull/error.hpp"
#include "occull/osg/osg_bench.hpp"
#include "occull/osg/scene_graph.hpp"
#include "occull/report.hpp"
#include "occull/scenes.hpp"

#include <fmt/format.h>
#include <osgDB/WriteFile>
#include <stb_image_write.h>

#include <algorithm>
#include <cstdio>
#include <iostream>

namespace occull::app {

namespace {

struct OsgArgs {
  BenchArgs run;  // scene, path, frames, warmup, fps, start, size, opts, repeat, verify, json, report
  std::string rows;
  std::string threading = "single";
  std::string export_file;
  std::string file;
  std::string png;
};

// `osg`: occull's cullers inside OpenSceneGraph beside OSG's OcclusionQueryNode.
int cmd_osg(const OsgArgs& a) {
  const BenchArgs& r = a.run;
  if (!a.export_file.empty()) {
    const occull::SceneBundle bundle = occull::make_scene(r.scene);
    const osgOccull::ExportedScene exported = osgOccull::export_scene(bundle.scene);
    if (!osgDB::writeNodeFile(*exported.root, a.export_file))
      throw occull::InputError(fmt::format("{}: OpenSceneGraph cannot write it (no plugin for its extension, or "
                                           "the folder is not writable)", a.export_file));
    std::fprintf(stderr, "exported %s (%zu objects) to %s\n", r.scene.c_str(), bundle.scene.objects().size(),
                 a.export_file.c_str());
    return 0;
  }
  if (occull::parse_api(r.api) != occull::Api::gl)
    throw occull::InputError("--api vulkan: occull osg renders through OpenSceneGraph, which draws with OpenGL");
  osgOccull::OsgBenchConfig c;
  c.scene = r.scene;
  c.file = a.file;
  c.path = r.path;
  c.rows = split_list(a.rows);
  c.frames = r.frames;
  c.warmup = r.warmup;
  c.repeat = r.repeat;
  c.sampling = {r.fps, r.start};
  const Size size = parse_size(r.size);
  c.width = size.width;
  c.height = size.height;
  c.verify = parse_on_off("--verify", r.verify);
  c.threading = a.threading;
  c.options = parse_options(r.opts);
  if (!a.png.empty())
    c.last_frame = [&](const std::string& row, int width, int height, const std::vector<std::uint8_t>& rgba) {
      std::string name = row;
      std::replace_if(name.begin(), name.end(), [](char ch) { return ch == ':' || ch == '=' || ch == '/'; }, '_');
      const std::string file = fmt::format("{}-{}.png", a.png, name);
      if (!stbi_write_png(file.c_str(), width, height, 4, rgba.data(), width * 4))
        throw occull::InputError(fmt::format("cannot write '{}'", file));
      std::fprintf(stderr, "wrote %s\n", file.c_str());
    };
  const bool report = !r.no_report && !r.report.empty();
  const auto json = open_output(r.json);
  if (report) occull::prepare_report_folder(r.report);
  Progress progress;
  const auto result = osgOccull::run_osg_bench(c, std::ref(progress));
  occull::print_table(result, std::cout);
  std::cout.flush();
  write_outputs(result, json.get(), r.json, nullptr, "", report ? r.report : std::string());
  return occull::verification_failures(result).empty() ? 0 : kExitVerificationFailed;
}

}  // namespace

Command add_osg(CLI::App& app) {
  auto a = std::make_shared<OsgArgs>();
  a->run.report.clear();
  auto* og = app.add_subcommand(
      "osg", "occull's cullers inside OpenSceneGraph beside OSG's own OcclusionQueryNode, in one headless OSG "
             "viewer, every frame checked against occull's ground truth");
  add_run_options(og, a->run, "row");
  og->add_option("--rows", a->rows,
                 "comma-separated rows (default: osg,oqn,oqn-strict,vfc,chcpp,nohc,grid):\n" +
                     osgOccull::describe_osg_rows());
  og->add_option("--threading", a->threading,
                 "osgViewer threading model: single (SingleThreaded) or cull-draw (CullDrawThreadPerContext); "
                 "the models that draw while the next frame is culled are refused")
      ->capture_default_str();
  og->add_option("--report", a->run.report, "write report.md, SVG charts, JSON and CSV into this folder");
  og->add_option("--file", a->file,
                 "instead of --scene: a file OSG reads (.osgt, .osgb, .ive, .obj, .3ds, .flt, ...), flown on its path "
                 "orbit or through (--path), verified against the ground truth of its triangles");
  og->add_option("--png", a->png,
                 "write each row's last frame (first repeat) as PREFIX-ROW.png: what OSG drew");
  og->add_option("--export", a->export_file,
                 "write the scene as an OSG file (.osgt, .osgb, .ive, ...: any format OSG writes) and exit");
  return [a] { return cmd_osg(*a); };
}

}  // namespace occull::app
