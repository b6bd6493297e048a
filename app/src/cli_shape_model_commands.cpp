#include "cli_shape_model_commands.h"

#include <chrono>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>

#include "cli_output.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/shape/correspond_skull.h"
#include "cranioplan/algorithms/shape/shape_model.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/sha256.h"

namespace cranioplan::cli {
namespace {

namespace fs = std::filesystem;

// The skull files in `inputs`: each file as given, each folder's files (not its sub-folders;
// a folder holding DICOM files only is one skull), in name order.
std::vector<std::string> skull_files(const std::vector<std::string>& inputs) {
  std::vector<std::string> out;
  for (const std::string& in : inputs) {
    std::error_code ec;
    if (!fs::is_directory(in, ec)) {
      out.push_back(in);
      continue;
    }
    std::vector<std::string> here;
    bool dicom_only = true;
    for (const auto& e : fs::directory_iterator(in, ec)) {
      if (!e.is_regular_file() && !e.is_directory()) continue;
      const std::string name = e.path().filename().string();
      if (name.empty() || name[0] == '.' || name == "README.md" || name == "DICOMDIR") continue;
      const std::string ext = e.path().extension().string();
      if (ext != ".dcm" && ext != "") dicom_only = false;
      here.push_back(e.path().string());
    }
    if (here.empty()) throw InputError(in, "the folder holds no skull files");
    if (dicom_only) {
      out.push_back(in);
      continue;
    }
    std::sort(here.begin(), here.end());
    out.insert(out.end(), here.begin(), here.end());
  }
  return out;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return text;
}

// "[=====     ] 12/35 name: message" on standard error (JSON or not: the result goes to
// standard output).
void progress(size_t done, size_t total, const std::string& what) {
  const int width = 30, filled = static_cast<int>(width * done / std::max<size_t>(1, total));
  std::cerr << '[' << std::string(filled, '=') << std::string(width - filled, ' ') << "] " << done
            << '/' << total << ' ' << what << std::endl;
}

Json statistics_json(const ShapeModel& m) {
  Json compact = Json::array();
  for (double c : m.statistics.compactness) compact.push_back(c);
  return Json{{"vertices", m.vertex_count()},
              {"outer_vertices", m.outer_count},
              {"triangles", m.triangles.size()},
              {"components", m.component_count()},
              {"skulls", m.provenance.skull_sha256.size()},
              {"compactness", compact},
              {"generalization_mm", m.statistics.generalization_mm},
              {"specificity_mm", m.statistics.specificity_mm},
              {"first_component_rms_mm",
               m.component_count() > 0 ? std::sqrt(m.variances(0) / m.vertex_count()) : 0.0},
              {"program_version", m.provenance.program_version},
              {"created_utc", m.provenance.created_utc},
              {"parameters", m.provenance.parameters_json}};
}

Subcommand add_build(CLI::App* parent, const bool& json) {
  struct Opts {
    std::vector<std::string> inputs;
    std::string output, template_skull;
    ExtractBoneSurfaceParams import;
    ShapeTemplateParams tmpl;
    ShapeModelBuildParams build;
    double min_matched = 0.6;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = parent->add_subcommand(
      "build", "Build a shape model of the normal skull from complete skulls (any pose)");
  cmd->add_option("DIR_OR_FILE", o->inputs,
                  "folders of complete skulls, or skull files (meshes, masks or CT volumes)")
      ->required();
  cmd->add_option("-o,--output", o->output, "the model to write (.cpsm)")->required();
  cmd->add_option("--template", o->template_skull,
                  "the skull whose vault the model's vertices are laid on (default: the first)");
  cmd->add_option("--threshold", o->import.threshold,
                  "bone threshold for volumes (default 300 HU for CT, 0.5 for masks)");
  cmd->add_option("--subdivisions", o->tmpl.subdivisions,
                  "of the template's icosahedron (5: 10,242 directions, about 3 mm apart)")
      ->check(CLI::Range(2, 6));
  cmd->add_option("--variance", o->build.variance_kept,
                  "share of the variance the components kept hold")
      ->check(CLI::Range(0.5, 1.0));
  cmd->add_option("--min-matched", o->min_matched,
                  "a skull whose correspondence brings less than this share of the template "
                  "within 2 mm of its bone is left out (with a warning)")
      ->check(CLI::Range(0.0, 1.0));
  return Subcommand{
      cmd, [o, &json]() -> int {
        std::vector<std::string> files = skull_files(o->inputs);
        if (!o->template_skull.empty()) {
          files.erase(std::remove(files.begin(), files.end(), o->template_skull), files.end());
          files.insert(files.begin(), o->template_skull);
        }
        if (files.size() < 3)
          throw InputError(o->inputs.front(),
                           "a shape model needs at least three complete skulls (" +
                               std::to_string(files.size()) + " given)");
        const auto t0 = std::chrono::steady_clock::now();
        ShapeTemplate tmpl;
        std::vector<Eigen::Matrix3Xd> corresponded;
        ShapeModelProvenance prov;
        std::vector<std::string> warnings;
        for (size_t i = 0; i < files.size(); ++i) {
          const std::string name = fs::path(files[i]).filename().string();
          const LoadedSkull skull = load_skull(files[i], o->import);
          if (i == 0) {
            tmpl = make_shape_template(skull.mesh, o->tmpl);
            if (tmpl.points.cols() == 0)
              throw InputError(files[i],
                               "no vault found to lay the model's template on (rays from "
                               "its centre do not cross one layer of bone)");
          }
          const Correspondence c = correspond_skull(tmpl, skull.mesh);
          const double s =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          char line[160];
          std::snprintf(line, sizeof line,
                        "%s: %.0f%% of the template within 2 mm, %.2f mm RMS (%.0f s)",
                        name.c_str(), 100.0 * c.matched, c.rms_mm, s);
          progress(i + 1, files.size(), line);
          if (!c.ok() || c.matched < o->min_matched) {
            warnings.push_back(
                files[i] + ": left out of the model: " + (c.ok() ? std::string(line) : c.message));
            continue;
          }
          corresponded.push_back(c.points);
          prov.skull_sha256.push_back(sha256_file(files[i]));
          prov.skull_names.push_back(name);
        }
        if (corresponded.size() < 3)
          throw InputError(o->inputs.front(),
                           "fewer than three skulls could be brought into "
                           "correspondence (see the warnings)");
        ShapeModel model =
            build_shape_model(corresponded, tmpl.outer_count, tmpl.triangles, o->build);
        prov.parameters_json = Json{
            {"template", fs::path(files.front()).filename().string()},
            {"subdivisions", o->tmpl.subdivisions},
            {"variance_kept", o->build.variance_kept},
            {"threshold", std::isfinite(o->import.threshold) ? Json(o->import.threshold) : Json()},
            {"min_matched",
             o->min_matched}}.dump();
        prov.program_version = CRANIOPLAN_VERSION;
        prov.created_utc = utc_now();
        model.provenance = prov;
        write_shape_model(model, o->output);
        Json j = statistics_json(model);
        j["output"] = o->output;
        j["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (!warnings.empty()) j["warnings"] = warnings;
        print_result(j, json);
        return kOk;
      }};
}

Subcommand add_info(CLI::App* parent, const bool& json) {
  auto path = std::make_shared<std::string>();
  auto* cmd = parent->add_subcommand("info",
                                     "Report a shape model: its size, provenance, "
                                     "compactness, generalisation and specificity");
  cmd->add_option("MODEL", *path, "shape model (.cpsm)")->required();
  return Subcommand{cmd, [path, &json]() -> int {
                      const ShapeModel m = read_shape_model(*path);
                      Json j = statistics_json(m);
                      Json skulls = Json::array();
                      for (size_t i = 0; i < m.provenance.skull_sha256.size(); ++i)
                        skulls.push_back(Json{{"name", m.provenance.skull_names[i]},
                                              {"sha256", m.provenance.skull_sha256[i]}});
                      j["skull_files"] = skulls;
                      print_result(j, json);
                      return kOk;
                    }};
}

}  // namespace

std::vector<Subcommand> add_shape_model_commands(CLI::App& app, const bool& json) {
  auto* group = app.add_subcommand(
      "shape-model", "Build and inspect statistical shape models of the normal skull");
  group->require_subcommand(1);
  return {add_build(group, json), add_info(group, json)};
}

}  // namespace cranioplan::cli
