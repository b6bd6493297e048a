#include "cli_evaluation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <map>
#include <memory>
#include <optional>

#include "cli_output.h"
#include "cli_planning.h"
#include "cranioplan/algorithms/alignment/mirror_mesh.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/geometry/voxelize_mesh.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/algorithms/quality/compare_implants.h"
#include "cranioplan/algorithms/quality/flap_defect.h"
#include "cranioplan/algorithms/quality/inject_defect.h"
#include "cranioplan/model/error.h"

namespace cranioplan::cli {
namespace {

namespace fs = std::filesystem;

// --shard I/N: the I-th (1-based) of N disjoint slices of the cases, item k going to slice
// k mod N: every case in exactly one shard, the same shard on every machine and run.
struct Shard {
  int index = 1, count = 1;
  bool takes(size_t k) const {
    return static_cast<int>(k % static_cast<size_t>(count)) == index - 1;
  }
};

void add_shard_options(CLI::App* cmd, Shard& shard, std::string& rows_out) {
  cmd->add_option_function<std::string>(
         "--shard",
         [&shard](const std::string& text) {
           int i = 0, n = 0;
           char slash = 0, extra = 0;
           if (std::sscanf(text.c_str(), "%d%c%d%c", &i, &slash, &n, &extra) != 3 || slash != '/' ||
               n < 1 || i < 1 || i > n)
             throw CLI::ValidationError("--shard",
                                        "expected I/N with 1 <= I <= N, not '" + text + "'");
           shard = {i, n};
         },
         "plan only the I-th of N disjoint slices of the cases (I/N, e.g. 2/8)")
      ->type_name("I/N");
  cmd->add_option("--rows-out", rows_out,
                  "folder to write each case's row to as JSON, for `merge` (created if missing)");
}

// Each row as FOLDER/<kind>-<key>.json, {"kind": ..., "row": ...}.
void write_row(const std::string& folder, const char* kind, const std::string& key,
               const Json& row) {
  if (folder.empty()) return;
  write_json_file(Json{{"kind", kind}, {"row", row}},
                  (fs::path(folder) / (std::string(kind) + "-" + key + ".json")).string());
}

void make_rows_folder(const std::string& folder) {
  if (folder.empty()) return;
  std::error_code ec;
  fs::create_directories(folder, ec);
  if (!fs::is_directory(folder)) throw InputError(folder, "cannot be made a folder (--rows-out)");
}

// FOLDER/K_<what>.stl for `study --cases-out`.
std::string case_file(const std::string& folder, int k, const char* what) {
  return (fs::path(folder) / (std::to_string(k) + "_" + what + ".stl")).string();
}

// A scored plan's row (evaluate, study): the method it used and its agreement with the truth.
void add_scores(Json& row, const AutoplanResult& r, const CompareResult& c) {
  row["method"] = to_string(r.method_used);
  row["dice"] = c.dice;
  row["boundary_dice"] = c.boundary_dice;
  row["hd95_mm"] = c.hd95_mm;
  // Whether the plan could go to the printer as it stands (the quality report's verdict).
  row["printable"] = r.quality.printable;
  row["rim_gap_mm"] = r.quality.rim_gap_mm;
  if (!r.quality.printable) row["not_printable_because"] = r.quality.reasons;
  row["model_share"] = r.sources.with_model;
  if (r.shape_fit) {
    if (r.shape_fit->measured()) row["shape_model_rms_mm"] = r.shape_fit->rms_mm;
    row["shape_model_used"] = r.method_used == PlanMethod::ShapeModel;
  }
}

// The printable verdict of a scored row, for the text table.
std::string printable_text(const Json& row) {
  if (!row.contains("printable")) return "";
  if (row["printable"].get<bool>()) return "printable  ";
  const Json& why = row["not_printable_because"];
  return "NOT printable (" + (why.empty() ? std::string("?") : why[0].get<std::string>()) + ")  ";
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// No figure where no case gave one (null, not 0).
Json median_or_null(const std::vector<double>& v) {
  return v.empty() ? Json(nullptr) : Json(median(v));
}

// The table's medians, from its rows alone: one run and its merged shards give the same.
Json evaluate_summary(const Json& rows) {
  std::vector<double> dsc, bdsc, hd95, secs;
  int failed = 0, unreadable = 0, printable = 0;
  for (const Json& row : rows) {
    const std::string status = row.at("status");
    if (status == status_name(AutoplanResult::Status::Planned)) {
      dsc.push_back(row.at("dice"));
      bdsc.push_back(row.at("boundary_dice"));
      hd95.push_back(row.at("hd95_mm"));
      printable += row.at("printable").get<bool>();
    } else if (status == status_name(AutoplanResult::Status::Failed) ||
               status == status_name(AutoplanResult::Status::NoDefect)) {
      // No implant overlaps nothing: a case not planned (no defect found, or a stage that
      // failed) counts as Dice 0 in the medians (as a missing prediction does in the
      // challenge); it has no distance.
      ++failed;
      dsc.push_back(0.0);
      bdsc.push_back(0.0);
    } else {
      ++unreadable;
    }
    if (!row.at("seconds").is_null()) secs.push_back(row.at("seconds"));
  }
  return Json{{"cases", rows.size()},
              {"printable", printable},
              {"failed", failed},
              {"bad_input", unreadable},
              {"median_dice", median_or_null(dsc)},
              {"median_boundary_dice", median_or_null(bdsc)},
              {"median_hd95_mm", median_or_null(hd95)},
              {"median_seconds", median_or_null(secs)}};
}

Json study_summary(const Json& rows) {
  std::vector<double> dsc, bdsc, hd95, secs;
  int printable = 0;
  for (const Json& row : rows) {
    if (row.contains("dice")) {
      dsc.push_back(row.at("dice"));
      bdsc.push_back(row.at("boundary_dice"));
      hd95.push_back(row.at("hd95_mm"));
      printable += row.at("printable").get<bool>();
    } else {
      dsc.push_back(0.0);
      bdsc.push_back(0.0);
    }
    if (row.contains("seconds")) secs.push_back(row.at("seconds"));
  }
  return Json{{"defects", rows.size()},         {"printable", printable},
              {"median_dice", median(dsc)},     {"median_boundary_dice", median(bdsc)},
              {"median_hd95_mm", median(hd95)}, {"median_seconds", median_or_null(secs)}};
}

// Every case is in the table; the exit code says whether all of them were planned.
int evaluate_exit(const Json& summary) {
  if (summary.at("bad_input").get<int>() > 0) return kBadInput;
  if (summary.at("failed").get<int>() > 0) return kUnusable;
  return kOk;
}

// The cases of a SkullFix-like folder: id → (defective skull, implant), in id order.
std::map<std::string, std::pair<std::string, std::string>> cases_in(const std::string& dir) {
  if (!fs::is_directory(dir)) throw InputError(dir, "is not a folder");
  std::map<std::string, std::pair<std::string, std::string>> cases;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    const size_t us = name.find('_');
    if (us == std::string::npos) continue;
    const std::string id = name.substr(0, us), rest = name.substr(us + 1);
    if (rest.rfind("defective_skull.", 0) == 0) cases[id].first = e.path().string();
    if (rest.rfind("implant.", 0) == 0) cases[id].second = e.path().string();
  }
  for (auto it = cases.begin(); it != cases.end();)
    it = it->second.first.empty() || it->second.second.empty() ? cases.erase(it) : std::next(it);
  if (cases.empty())
    throw InputError(dir, "holds no NNN_defective_skull.* with an NNN_implant.* beside it");
  return cases;
}

// One case of `evaluate`: planned and scored, or its unreadable file as its row.
Json evaluate_case(const std::string& id, const std::string& defective,
                   const std::string& truth_path, const AutoplanParams& params,
                   const std::string& implants_out, const ShapeModel* model) {
  Json row{{"case", id}};
  try {
    // The truth is read first (to fail before planning) and not timed: the time is the
    // plan's, from reading the skull to the implant.
    const SkullMesh truth = load_any(truth_path);
    if (model) {
      // A model built with this case's complete skull (SkullFix's NNN_complete_skull beside
      // its defective one) has seen the answer.
      std::string complete = defective;
      const size_t at = complete.rfind("defective_skull");
      if (at != std::string::npos) complete.replace(at, 15, "complete_skull");
      std::error_code ec;
      if (at != std::string::npos && fs::exists(complete, ec)) refuse_if_in_model(*model, complete);
    }
    const auto t0 = std::chrono::steady_clock::now();
    const LoadedSkull loaded = load_skull(defective);
    const SkullMesh& skull = loaded.mesh;
    const AutoplanResult r = autoplan(skull, Landmarks{}, planning(params, loaded), model);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    row["status"] = status_name(r.status);
    row["message"] = r.message;
    if (r.planned()) {
      const CompareResult c = compare_implants(r.implant.mesh, truth, &skull);
      if (!implants_out.empty()) {
        const std::string path = (fs::path(implants_out) / (id + "_planned_implant.stl")).string();
        write_mesh(r.implant.mesh, path, loaded.file_space);
        row["implant"] = path;
      }
      add_scores(row, r, c);
    }
    row["seconds"] = seconds;
  } catch (const Error& e) {
    // One case's unreadable file is that case's row, not the end of the run.
    row["status"] = "bad_input";
    row["message"] = e.what();
    row["seconds"] = nullptr;  // no plan, no time
  }
  return row;
}

void print_evaluate_row(const Json& row) {
  if (row["status"] == "planned")
    std::cout << row["case"].get<std::string>() << "  " << row["method"].get<std::string>()
              << "  DSC " << row["dice"].get<double>() << "  bDSC "
              << row["boundary_dice"].get<double>() << "  HD95 " << row["hd95_mm"].get<double>()
              << " mm  " << row["seconds"].get<double>() << " s  " << printable_text(row)
              << row["message"].get<std::string>() << std::endl;
  else
    std::cout << row["case"].get<std::string>() << "  " << row["status"].get<std::string>() << "  "
              << row["message"].get<std::string>() << std::endl;
}

// evaluate
Subcommand add_evaluate(CLI::App& app, const bool& json) {
  struct Opts {
    std::string dir, implants_out, rows_out, shape_model;
    AutoplanParams params;
    Shard shard;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "evaluate",
      "Autoplan every NNN_defective_skull.* against its NNN_implant.* (exit 1 if a case could "
      "not be planned, 3 if a case's file could not be read; every case is in the table)");
  cmd->add_option("CASES_DIR", o->dir, "folder of cases (meshes or NRRD/NIfTI masks)")->required();
  cmd->add_option("--implants-out", o->implants_out,
                  "folder to write each planned implant to (NNN_planned_implant.stl)");
  add_shard_options(cmd, o->shard, o->rows_out);
  add_fit_option(cmd, o->params);
  add_shape_model_option(cmd, o->shape_model);
  return Subcommand{cmd, [o, &json] {
                      if (!o->implants_out.empty() && !fs::is_directory(o->implants_out))
                        throw InputError(o->implants_out, "is not a folder (--implants-out)");
                      const auto cases = cases_in(o->dir);
                      const auto model = shape_model_from(o->shape_model);
                      make_rows_folder(o->rows_out);
                      Json rows = Json::array();
                      size_t k = 0;
                      for (const auto& [id, files] : cases) {
                        if (!o->shard.takes(k++)) continue;
                        const Json row = evaluate_case(id, files.first, files.second, o->params,
                                                       o->implants_out, model.get());
                        if (!json) print_evaluate_row(row);
                        write_row(o->rows_out, "evaluate", id, row);
                        rows.push_back(row);
                      }
                      const Json summary = evaluate_summary(rows);
                      if (json)
                        print_result(Json{{"cases", rows}, {"median", summary}}, true);
                      else
                        print_result(Json{{"median", summary}}, false);
                      return evaluate_exit(summary);
                    }};
}

// The sphere defects of `study`: directions on the upper vault, alternately left and right,
// spread by the golden angle; each defect's centre in the middle of the bone along that ray
// from the vertex centroid, its diameter between the sizes asked.
std::optional<InjectDefectParams> sphere_defect(const SkullMesh& skull, const SurfaceLocator& bone,
                                                int k, double min_size, double max_size) {
  const Eigen::Vector3d centroid = vertex_centroid(skull);
  const double side = k % 2 == 0 ? 1.0 : -1.0;
  const double phi = 2.39996 * k, up = 0.25 + 0.5 * std::fmod(0.618034 * k, 1.0);
  const Eigen::Vector3d dir =
      Eigen::Vector3d(side * (0.55 + 0.25 * std::abs(std::cos(phi))), 0.6 * std::sin(phi), up)
          .normalized();
  const auto out_hit = bone.first_hit(centroid + 400.0 * dir, centroid);
  const auto in_hit = bone.first_hit(centroid, centroid + 400.0 * dir);
  if (!out_hit || !in_hit) return std::nullopt;
  InjectDefectParams ip;
  ip.center = 0.5 * (out_hit->point + in_hit->point);
  ip.size_mm = min_size + (max_size - min_size) * std::fmod(0.381966 * (k + 1), 1.0);
  ip.voxel_mm = 0.5;
  return ip;
}

// The flaps of `study --shape flap|bifrontal`: the k-th of a series whose sizes, sides and
// margins are spread by the golden ratio over a decompressive craniectomy's: one-sided 130-150
// mm front to back and 100-120 mm high, 15-20 mm off the midline, 5-15° in front of the vault's
// centre, alternately left and right; bifrontal 180-220 mm side to side and 90-110 mm front to
// back, alternately in one piece and with a 20 mm bar over the midline.
FlapPlacementParams flap_series(bool bifrontal, int k) {
  const double a = std::fmod(0.381966 * (k + 1), 1.0), b = std::fmod(0.618034 * (k + 1), 1.0);
  FlapPlacementParams p;
  if (bifrontal) {
    p.kind = FlapPlacementParams::Kind::Bifrontal;
    p.length_mm = 180.0 + 40.0 * a;
    p.width_mm = 90.0 + 20.0 * b;
    p.midline_margin_mm = k % 2 == 0 ? 0.0 : 10.0;
    p.above_floor_mm = 10.0;
  } else {
    p.side = k % 2 == 0 ? 1 : -1;
    p.length_mm = 130.0 + 20.0 * a;
    p.width_mm = 100.0 + 20.0 * b;
    p.midline_margin_mm = 15.0 + 5.0 * b;
    p.forward_deg = 5.0 + 10.0 * a;
  }
  return p;
}

// The points a user would click to choose the flap's openings: its centre, or, with a bar over
// the midline, the centre of each half.
std::vector<Eigen::Vector3d> flap_points(const FlapPlacement& placed) {
  const FlapCut& cut = *placed.cut;
  const double r = placed.outer_radius_mm;
  if (cut.one_side != 0 || cut.midline_margin_mm <= 0.0) return {cut.apex + r * cut.axis};
  std::vector<Eigen::Vector3d> points;
  for (double s : {-0.5, 0.5}) {
    const double angle = s * cut.half_length_rad;
    points.push_back(cut.apex +
                     r * (std::cos(angle) * cut.axis + std::sin(angle) * cut.along).normalized());
  }
  return points;
}

// The registered mirror of the complete skull within the defect's shape against the removed
// bone (Dice on a 0.5 mm grid): an implant that followed the healthy side exactly, with the rim
// exactly where the cut was, would score this. What stands between it and 1 is the skull's own
// asymmetry (and the registration's error).
double mirror_oracle_dice(const SkullMesh& complete, const AutoplanResult& r,
                          const InjectDefectParams& shape, const SkullMesh& truth) {
  const SkullMesh mirrored =
      transform_mesh(mirror_mesh(complete, r.plane.plane), r.registration.transform);
  auto [lo, hi] = mesh_bounds(truth);
  const VoxelGrid grid = VoxelGrid::covering(lo - Eigen::Vector3d::Constant(5.0),
                                             hi + Eigen::Vector3d::Constant(5.0), 0.5);
  const std::vector<uint8_t> t = voxelize_mesh(truth, grid), m = voxelize_mesh(mirrored, grid);
  double both = 0.0, sum = 0.0;
  for (int k = 0; k < grid.dims[2]; ++k)
    for (int j = 0; j < grid.dims[1]; ++j)
      for (int i = 0; i < grid.dims[0]; ++i) {
        const size_t idx = grid.index(i, j, k);
        const bool mirror_in = m[idx] && in_defect(shape, grid.center(i, j, k));
        both += mirror_in && t[idx];
        sum += mirror_in + (t[idx] != 0);
      }
  return sum > 0.0 ? 2.0 * both / sum : 0.0;
}

// The meshes as one (their vertices and triangles side by side).
SkullMesh joined(const std::vector<const SkullMesh*>& meshes) {
  TriangleSoup all;
  for (const SkullMesh* m : meshes) {
    const TriangleSoup s = to_soup(*m);
    const int base = static_cast<int>(all.vertices.size());
    all.vertices.insert(all.vertices.end(), s.vertices.begin(), s.vertices.end());
    for (auto t : s.triangles) {
      for (auto& v : t) v += base;
      all.triangles.push_back(t);
    }
  }
  return build_mesh(all);
}

// The k-th defect of `study`: its cut, the points a user would click to choose its openings,
// and what its row says of it.
struct StudyDefect {
  InjectDefectParams cut;
  std::vector<Eigen::Vector3d> points;
};

// A sphere of the series (sphere_defect); none when it does not fit the skull.
std::optional<StudyDefect> sphere_study_defect(const SkullMesh& skull, const SurfaceLocator& bone,
                                               int k, double min_size, double max_size, Json& row) {
  const auto sphere = sphere_defect(skull, bone, k, min_size, max_size);
  if (!sphere) return std::nullopt;
  row["center"] = to_json(sphere->center);
  row["size_mm"] = sphere->size_mm;
  return StudyDefect{*sphere, {sphere->center}};
}

// A flap of the series (flap_series), placed on the skull whose midsagittal plane is `plane`;
// a skull it cannot be placed on is bad input (`file` named).
std::optional<StudyDefect> flap_study_defect(const std::string& file, const SkullMesh& skull,
                                             const SurfaceLocator& bone, const Plane& plane,
                                             bool bifrontal, int k, Json& row) {
  const FlapPlacementParams fp = flap_series(bifrontal, k);
  const FlapPlacement placed = place_flap(skull, bone, plane, fp);
  if (!placed.cut) throw InputError(file, placed.message);
  StudyDefect d;
  d.cut.shape = InjectDefectParams::Shape::Flap;
  d.cut.flap = *placed.cut;
  d.cut.voxel_mm = 0.5;
  d.points = flap_points(placed);
  row["flap"] = placed.message;
  row["length_mm"] = fp.length_mm;
  row["width_mm"] = fp.width_mm;
  row["midline_margin_mm"] = placed.cut->midline_margin_mm;
  return d;
}

// The plans of one study defect (one per opening it made) scored together against the bone
// removed, into `row`: their messages, and when all planned the scores of their implants
// joined, the mirror's alone, the quality verdicts. The joined implant, or none.
std::optional<SkullMesh> score_study_plans(const std::vector<AutoplanResult>& plans,
                                           const SkullMesh& skull, const InjectDefectParams& ip,
                                           const InjectDefectResult& d, Json& row) {
  std::string message;
  std::vector<const SkullMesh*> implants;
  bool all_planned = true, all_printable = true;
  double worst_gap = 0.0;
  for (const AutoplanResult& r : plans) {
    message += (message.empty() ? "" : " | ") + r.message;
    all_planned = all_planned && r.planned();
    if (!r.planned()) continue;
    implants.push_back(&r.implant.mesh);
    all_printable = all_printable && r.quality.printable;
    worst_gap = std::max(worst_gap, r.quality.rim_gap_mm);
  }
  row["message"] = message;
  row["implants"] = plans.size();
  if (!all_planned) return std::nullopt;
  SkullMesh implant;
  if (implants.size() == 1)
    implant = *implants.front();
  else
    implant = joined(implants);
  add_scores(row, plans.front(), compare_implants(implant, d.implant, &d.defective));
  row["mirror_dice"] = mirror_oracle_dice(skull, plans.front(), ip, d.implant);
  row["printable"] = all_printable;
  row["rim_gap_mm"] = worst_gap;
  Json why = Json::array();
  for (const AutoplanResult& r : plans)
    for (const std::string& reason : r.quality.reasons) why.push_back(reason);
  if (!all_printable) row["not_printable_because"] = why;
  return implant;
}

Subcommand add_study(CLI::App& app, const bool& json) {
  struct Opts {
    std::string skull, shape = "sphere", cases_out, method = "auto";
    int count = 10;
    std::optional<double> min_size, max_size;
    AutoplanParams params;
    Shard shard;
    std::string rows_out, shape_model;
  };
  auto o = std::make_shared<Opts>();
  auto* cmd = app.add_subcommand(
      "study",
      "Cut defects out of a healthy skull (spheres, or the flaps of decompressive "
      "craniectomies), autoplan and score each");
  cmd->add_option("SKULL", o->skull, "healthy skull (mesh or volume)")->required();
  cmd->add_option("--count", o->count, "number of defects (default 10)")->check(CLI::Range(1, 100));
  cmd->add_option("--shape", o->shape,
                  "sphere (one-sided, on the upper vault), flap (a one-sided decompressive "
                  "craniectomy: 130-150 x 100-120 mm, 15-20 mm off the midline, down to the "
                  "temporal floor) or bifrontal (across the forehead, in one piece or two)")
      ->capture_default_str()
      ->check(CLI::IsMember({"sphere", "flap", "bifrontal"}));
  cmd->add_option("--min-size", o->min_size, "smallest sphere diameter (mm; default 30)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--max-size", o->max_size, "largest sphere diameter (mm; default 50)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--method", o->method, "auto, mirror, rim-only or model (as autoplan's)")
      ->capture_default_str()
      ->check(CLI::IsMember({"auto", "mirror", "rim-only", "model"}));
  cmd->add_option("--cases-out", o->cases_out,
                  "folder to write each defective skull, its truth and its plan to "
                  "(K_defective.stl, K_truth.stl, K_planned.stl)");
  add_shard_options(cmd, o->shard, o->rows_out);
  add_fit_option(cmd, o->params);
  add_shape_model_option(cmd, o->shape_model);
  return Subcommand{
      cmd, [o, &json] {
        const bool spheres = o->shape == "sphere";
        const auto model = shape_model_from(o->shape_model);
        if (model) refuse_if_in_model(*model, o->skull);
        if (o->method == "model" && !model)
          throw CLI::ValidationError("--method model", "needs --shape-model FILE");
        plan_method_from_string(o->method, o->params.propose.method);
        if (!spheres && (o->min_size || o->max_size))
          throw CLI::ValidationError("--min-size/--max-size", "are sizes of --shape sphere");
        if (!o->cases_out.empty()) make_rows_folder(o->cases_out);
        const LoadedSkull loaded = load_skull(o->skull);
        const SkullMesh& skull = loaded.mesh;
        const SurfaceLocator bone(skull);
        std::optional<Plane> plane;
        if (!spheres) {
          const PlaneFit fit = fit_sagittal_plane(skull, Landmarks{});
          if (!fit.usable()) throw InputError(o->skull, "midsagittal plane: " + fit.message);
          plane = fit.plane;
        }
        make_rows_folder(o->rows_out);
        Json rows = Json::array();
        for (int k = 0; k < o->count; ++k) {
          if (!o->shard.takes(static_cast<size_t>(k))) continue;
          Json row{{"defect", k}};
          const std::optional<StudyDefect> defect =
              spheres ? sphere_study_defect(skull, bone, k, o->min_size.value_or(30.0),
                                            o->max_size.value_or(50.0), row)
                      : flap_study_defect(o->skull, skull, bone, *plane, o->shape == "bifrontal", k,
                                          row);
          if (!defect) continue;
          const InjectDefectParams& ip = defect->cut;
          const std::vector<Eigen::Vector3d>& points = defect->points;
          const InjectDefectResult d = inject_defect(skull, ip);
          if (!d.usable()) continue;
          // The skull may have a defect of its own (the sample has): the planner is told
          // which opening is meant, as a user would point at it (at each, for two).
          std::vector<AutoplanResult> plans;
          const auto t0 = std::chrono::steady_clock::now();
          for (const Eigen::Vector3d& point : points) {
            AutoplanParams params = o->params;
            params.propose.detect.near = point;
            plans.push_back(autoplan(d.defective, Landmarks{}, params, model.get()));
          }
          row["seconds"] =
              std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
          const std::optional<SkullMesh> implant = score_study_plans(plans, skull, ip, d, row);
          if (implant && !o->cases_out.empty())
            write_mesh(*implant, case_file(o->cases_out, k, "planned"), loaded.file_space);
          if (!o->cases_out.empty()) {
            write_mesh(d.defective, case_file(o->cases_out, k, "defective"), loaded.file_space);
            write_mesh(d.implant, case_file(o->cases_out, k, "truth"), loaded.file_space);
          }
          if (!json)
            std::cout << k << "  "
                      << (spheres ? "size " + std::to_string(ip.size_mm) + " mm"
                                  : row["flap"].get<std::string>())
                      << "  " << row.value("method", "-") << "  DSC " << row.value("dice", 0.0)
                      << "  bDSC " << row.value("boundary_dice", 0.0) << "  HD95 "
                      << row.value("hd95_mm", 0.0) << " mm  " << row["seconds"].get<double>()
                      << " s  " << printable_text(row) << row["message"].get<std::string>()
                      << std::endl;
          write_row(o->rows_out, "study", std::to_string(k), row);
          rows.push_back(row);
        }
        const Json summary = study_summary(rows);
        if (json)
          print_result(Json{{"defects", rows}, {"median", summary}}, true);
        else
          print_result(Json{{"median", summary}}, false);
        return kOk;
      }};
}

// merge
Subcommand add_merge(CLI::App& app, const bool& json) {
  auto folders = std::make_shared<std::vector<std::string>>();
  auto* cmd = app.add_subcommand(
      "merge", "The table and medians of evaluate or study shards (--rows-out folders) as one run");
  cmd->add_option("FOLDERS", *folders, "folders the shards wrote their rows to")->required();
  return Subcommand{
      cmd, [folders, &json] {
        std::string kind;
        std::map<std::string, Json> evaluate_rows;
        std::map<int, Json> study_rows;
        for (const std::string& folder : *folders) {
          if (!fs::is_directory(folder)) throw InputError(folder, "is not a folder");
          for (const auto& e : fs::directory_iterator(folder)) {
            if (e.path().extension() != ".json") continue;
            const std::string path = e.path().string();
            const Json j = read_json_file(path);
            if (!j.is_object() || !j.contains("kind") || !j.contains("row"))
              throw InputError(path, "is not a row of evaluate or study");
            const std::string k = j["kind"].get<std::string>();
            if (!kind.empty() && k != kind)
              throw InputError(path, "is a row of " + k + ", the others of " + kind);
            kind = k;
            // A case in two shards (folders of two runs mixed up) is an error.
            const bool fresh = k == "evaluate"
                                   ? evaluate_rows.emplace(j["row"].at("case"), j["row"]).second
                                   : study_rows.emplace(j["row"].at("defect"), j["row"]).second;
            if (!fresh) throw InputError(path, "repeats a case another shard wrote");
          }
        }
        if (kind.empty()) throw InputError(folders->front(), "holds no rows (evaluate --rows-out)");
        Json rows = Json::array();
        for (const auto& [key, row] : evaluate_rows) rows.push_back(row);
        for (const auto& [key, row] : study_rows) rows.push_back(row);
        const bool evaluate = kind == "evaluate";
        const Json summary = evaluate ? evaluate_summary(rows) : study_summary(rows);
        if (json)
          print_result(Json{{evaluate ? "cases" : "defects", rows}, {"median", summary}}, true);
        else
          print_result(Json{{"median", summary}}, false);
        return evaluate ? evaluate_exit(summary) : kOk;
      }};
}

}  // namespace

std::vector<Subcommand> add_evaluation_commands(CLI::App& app, const bool& json) {
  return {add_evaluate(app, json), add_study(app, json), add_merge(app, json)};
}

}  // namespace cranioplan::cli
