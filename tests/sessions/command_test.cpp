#include "cranioplan/sessions/command.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <tuple>
#include <type_traits>

#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/io/write_mesh.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/session.h"
#include "cranioplan/sessions/session_error.h"
#include "cranioplan/sessions/sha256.h"
#include "support/session_cases.h"
#include "support/synthetic.h"
#include "support/test_files.h"

namespace cranioplan {
namespace {

namespace fs = std::filesystem;
using test::push_ok;

TEST(Commands, EveryTypeRoundTripsThroughJson) {
  std::vector<Command> all = {
      commands::load_skull("skull.stl", {}, std::string(64, 'a')),
      commands::set_landmark("nasion", {1, 2, 3}),
      commands::clear_landmark("midline"),
      commands::fit_plane(),
      commands::adjust_plane({0, 0, 1}, 2.5, -1.0),
      commands::mirror(),
      commands::register_mirror(),
      commands::move_mirrored({0, 1, 0}, 1.0, {1, 2, 3}, {0.5, 0, 0}),
      commands::set_clip_plane(Plane{Eigen::Vector3d::UnitZ(), 12.0}),
      commands::add_marker(MarkerType::InnerSurface, {4, 5, 6}),
      commands::move_marker(3, {7, 8, 9}),
      commands::delete_marker(3),
      commands::retype_marker(4, MarkerType::OuterEdge),
      commands::import_markers({{1, MarkerType::OuterEdge, {1, 1, 1}, MarkerSurface::Original}},
                               "m.json", std::string(64, 'b')),
      commands::clear_markers(),
      commands::propose_markers(),
      commands::smooth_markers({8.0, 3.0, 2}, false),
      commands::build_implant(),
      commands::export_implant("implant.ply", std::string(64, 'c')),
      commands::go_to_step(4),
      commands::complete_step(4),
      commands::note("checked with the surgeon"),
      commands::attach_ct("ct.nrrd", {}, std::string(64, 'd')),
      commands::approve("Dr A", "neurosurgeon", std::string(64, 'e')),
      commands::export_implant("implant.3mf", std::string(64, 'f'), MouldParams{}),
  };
  RegisterParams with_roi;
  with_roi.roi = RegionOfInterest{RegionOfInterest::Shape::Box, {1, 2, 3}, 10, {4, 5, 6}};
  all.push_back(commands::register_mirror(with_roi));
  std::set<CommandType> seen;
  for (const Command& c : all) {
    seen.insert(c.type);
    const Json j = to_json(c);
    const Command back = command_from_json(j, "test");
    EXPECT_EQ(to_json(back), j) << type_tag(c.type);
    EXPECT_FALSE(describe(c).empty());
  }
  EXPECT_EQ(seen.size(), all_command_types().size()) << "a command type has no round-trip case";
  // Parameters read back into the algorithms' structs equal what was written.
  RegisterParams back;
  params_from_json(ParamReader(all.back().params["params"], "test"), back);
  ASSERT_TRUE(back.roi);
  EXPECT_EQ(back.roi->half_size, Eigen::Vector3d(4, 5, 6));
  ImplantParams implant;
  implant.thickness_mm = 5.5;
  implant.radial_center = Eigen::Vector3d(1, 2, 3);
  ImplantParams implant_back;
  params_from_json(ParamReader(params_to_json(implant), "test"), implant_back);
  EXPECT_EQ(implant_back.thickness_mm, 5.5);
  EXPECT_EQ(*implant_back.radial_center, Eigen::Vector3d(1, 2, 3));
  ImplantParams nan_thickness;  // NaN (the default: measured) goes through JSON as null
  params_from_json(ParamReader(params_to_json(nan_thickness), "test"), implant_back);
  EXPECT_TRUE(std::isnan(implant_back.thickness_mm));
}

// A build_implant of version 1 (written before fitting to the bone existed) still applies:
// read as recorded, built without the fit.
TEST(Commands, BuildImplantVersionOneIsReadByItsOwnRules) {
  Json v1 = to_json(commands::build_implant());
  EXPECT_EQ(v1["version"], 14);
  v1["version"] = 1;
  v1["params"]["params"].erase("trim");
  v1["params"]["params"].erase("fit_to_bone_mm");
  const Command c = command_from_json(v1, "old plan");
  EXPECT_EQ(c.version, 1);
  EXPECT_EQ(to_json(c), v1) << "kept as recorded: the journal's hashes cover it";
}

// load_skull 4 reads volumes in the patient's frame, a DICOM folder's named series, and drops a
// mesh's far pieces; a plan saved before (no such fields) reads its skull as it was then.
TEST(Commands, PlansSavedBeforeThePatientFrameReadTheirSkullAsThen) {
  ExtractBoneSurfaceParams now;
  now.dicom_series = "1.2.3";
  const Json load = to_json(commands::load_skull("ct", now));
  ExtractBoneSurfaceParams back;
  params_from_json(ParamReader(load["params"]["import"], "test"), back);
  EXPECT_TRUE(back.patient_frame);
  EXPECT_TRUE(back.drop_far_pieces);
  EXPECT_EQ(back.dicom_series, "1.2.3");
  Json old = load["params"]["import"];
  for (const char* k : {"patient_frame", "drop_far_pieces", "dicom_series"}) old.erase(k);
  params_from_json(ParamReader(old, "test"), back);
  EXPECT_FALSE(back.patient_frame);
  EXPECT_FALSE(back.drop_far_pieces);
  EXPECT_EQ(back.dicom_series, "");
}

// Older plans replay to the implants they exported: a load_skull 1 reads the skull as the file
// gave it, not in canonical form, and a build_implant 1 or 2 fits to the bone as it was made
// to (slivers under 1.25 mm removed, cracks under 2 mm bridged). Today's commands record both,
// and read them back as recorded.
TEST(Commands, OlderPlansReadTheSkullAndFitTheBoneAsTheyWereMade) {
  const Json load = to_json(commands::load_skull("skull.stl"));
  EXPECT_EQ(load["version"], 6);
  ExtractBoneSurfaceParams import;
  params_from_json(ParamReader(load["params"]["import"], "test"), import);
  EXPECT_TRUE(import.canonical);
  Json old_load = load["params"]["import"];
  old_load.erase("canonical");
  params_from_json(ParamReader(old_load, "test"), import);
  EXPECT_FALSE(import.canonical);

  ImplantParams p;
  p.trim.min_feature_mm = 1.7;
  p.trim.bridge_mm = 0.8;
  const Json build = to_json(commands::build_implant(p));
  EXPECT_EQ(build["version"], 14);
  ImplantParams back;
  params_from_json(ParamReader(build["params"]["params"], "test"), back);
  EXPECT_EQ(back.trim.min_feature_mm, 1.7);
  EXPECT_EQ(back.trim.bridge_mm, 0.8);
  EXPECT_EQ(back.trim.voxel_mm, p.trim.voxel_mm);
  Json old_build = build["params"]["params"];
  old_build.erase("trim");
  params_from_json(ParamReader(old_build, "test"), back);
  EXPECT_EQ(back.trim.min_feature_mm, 1.25);
  EXPECT_EQ(back.trim.bridge_mm, 1.0);
  EXPECT_EQ(ImplantParams{}.trim.min_feature_mm, 1.5) << "today's default";
  EXPECT_FALSE(back.trim.clearance_mm.has_value()) << "build_implant 2: the bone grown by a voxel";
  EXPECT_FALSE(back.trim.thin_fills_removed);
  EXPECT_FALSE(back.trim.vote_through_holes);
}

// build_implant 5 decides the skull's inside by votes where its surface is open; version 4 (no
// "vote_through_holes") by parity along z, as it fitted its implants.
TEST(Commands, PlansSavedBeforeVotingThroughHolesFitTheBoneAsThen) {
  const Json build = to_json(commands::build_implant(ImplantParams{}));
  EXPECT_EQ(build["params"]["params"]["trim"]["vote_through_holes"], true);
  ImplantParams back;
  params_from_json(ParamReader(build["params"]["params"], "test"), back);
  EXPECT_TRUE(back.trim.vote_through_holes);
  Json v4 = build["params"]["params"];
  v4["trim"].erase("vote_through_holes");
  params_from_json(ParamReader(v4, "test"), back);
  EXPECT_FALSE(back.trim.vote_through_holes);
  EXPECT_TRUE(back.trim.thin_fills_removed) << "the rest of version 4 as recorded";
}

// build_implant 6 records the material, the clearance zones and the perforations in full (a replay
// uses the values of the day, not the presets of a later version); version 5 reads with neither. A
// material out of its ranges in a file is refused with the value named.
TEST(Commands, TheBuildRecordsItsMaterialAndClearanceZones) {
  ImplantParams p;
  p.fit_to_bone_mm = 4.0;
  p.material = *material_preset("pmma");
  p.material->edge_clearance_mm = 1.5;
  p.clearance_zones = {{Eigen::Vector3d(1, 2, 3), 12.0, 2.5}};
  p.perforations.pattern = true;
  p.perforations.spacing_mm = 12.0;
  p.perforations.added = {Eigen::Vector3d(4, 5, 6)};
  p.perforations.removed = {Eigen::Vector3d(7, 8, 9)};
  const Json build = to_json(commands::build_implant(p));
  EXPECT_EQ(build["version"], 14);
  const Json& recorded = build["params"]["params"];
  EXPECT_EQ(recorded["material"]["name"], "PMMA");
  EXPECT_TRUE(recorded["material"]["thickness_mm"].is_null()) << "follows the bone";
  ImplantParams back;
  params_from_json(ParamReader(recorded, "test"), back);
  ASSERT_TRUE(back.material);
  EXPECT_EQ(back.material->id, "pmma");
  EXPECT_EQ(back.material->edge_clearance_mm, 1.5);
  EXPECT_EQ(back.material->under_contour_mm, 0.5);
  EXPECT_TRUE(std::isnan(back.material->thickness_mm));
  EXPECT_EQ(back.material->density_g_cm3, 1.18);
  ASSERT_EQ(back.clearance_zones.size(), 1u);
  EXPECT_EQ(back.clearance_zones[0].center, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(back.clearance_zones[0].clearance_mm, 2.5);
  EXPECT_TRUE(back.perforations.pattern);
  EXPECT_EQ(back.perforations.spacing_mm, 12.0);
  ASSERT_EQ(back.perforations.added.size(), 1u);
  EXPECT_EQ(back.perforations.added[0], Eigen::Vector3d(4, 5, 6));
  ASSERT_EQ(back.perforations.removed.size(), 1u);

  Json v5 = recorded;
  v5.erase("material");
  v5.erase("clearance_zones");
  v5.erase("perforations");
  params_from_json(ParamReader(v5, "test"), back);
  EXPECT_FALSE(back.material);
  EXPECT_FALSE(back.perforations.any());
  EXPECT_TRUE(back.clearance_zones.empty());

  Json bad = recorded;
  bad["material"]["edge_clearance_mm"] = 7.0;
  try {
    params_from_json(ParamReader(bad, "plan.json"), back);
    ADD_FAILURE() << "a clearance of 7 mm was read";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("edge clearance must be 0 to 3 mm (7 given)"),
              std::string::npos)
        << e.what();
  }
}

// build_implant 7 records the fixation tabs in full (the midline plane they kept off, the user's
// positions, the sizes left to the material as null); version 6 reads without tabs. A tab out
// of its ranges in a file is refused with the value named.
TEST(Commands, TheBuildRecordsItsTabs) {
  ImplantParams p;
  p.fit_to_bone_mm = 4.0;
  p.tabs.automatic = true;
  p.tabs.count = 5;
  p.tabs.screws = 2;
  p.tabs.length_mm = 20.0;
  p.tabs.positions = {Eigen::Vector3d(1.5, 2.25, -3.125)};
  p.tabs.midline = Plane{Eigen::Vector3d(0.6, 0.8, 0.0), -12.5};
  const Json recorded = to_json(commands::build_implant(p))["params"]["params"];
  EXPECT_TRUE(recorded["tabs"]["width_mm"].is_null()) << "from the material";
  ImplantParams back;
  params_from_json(ParamReader(recorded, "test"), back);
  EXPECT_TRUE(back.tabs.automatic);
  EXPECT_EQ(back.tabs.count, 5);
  EXPECT_EQ(back.tabs.screws, 2);
  EXPECT_EQ(back.tabs.length_mm, 20.0);
  EXPECT_TRUE(std::isnan(back.tabs.width_mm));
  EXPECT_TRUE(std::isnan(back.tabs.thickness_mm));
  ASSERT_EQ(back.tabs.positions.size(), 1u);
  EXPECT_EQ(back.tabs.positions[0], Eigen::Vector3d(1.5, 2.25, -3.125));
  ASSERT_TRUE(back.tabs.midline);
  EXPECT_EQ(back.tabs.midline->normal, Eigen::Vector3d(0.6, 0.8, 0.0));
  EXPECT_EQ(back.tabs.midline->offset, -12.5);
  EXPECT_EQ(to_json(commands::build_implant(back))["params"]["params"], recorded);

  Json v6 = recorded;
  v6.erase("tabs");
  params_from_json(ParamReader(v6, "test"), back);
  EXPECT_FALSE(back.tabs.any());

  Json bad = recorded;
  bad["tabs"]["length_mm"] = 40.0;
  try {
    params_from_json(ParamReader(bad, "plan.json"), back);
    ADD_FAILURE() << "a tab 40 mm long was read";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("length must be 4 to 25 mm (40 given)"), std::string::npos)
        << e.what();
  }
}

// The manufacturing parameters are declared once (for_each_field): every default lies in its
// range, the session writes exactly the declared fields in the declared order and reads them
// back, the CLI options of tabs and holes (given to the same subcommands) do not clash, and a
// value out of its declared range is refused by the reader in the declaration's words.
template <class P>
std::vector<std::string> declared_keys(std::set<std::string>* options) {
  std::vector<std::string> keys;
  P p;
  for_each_field(
      [&](const ParamSpec& s, auto& value) {
        keys.push_back(s.key);
        using T = std::decay_t<decltype(value)>;
        if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
          if (s.ranged()) {
            EXPECT_TRUE(s.allows(static_cast<double>(value))) << s.key << " default out of range";
          }
        }
        if (s.option) {
          EXPECT_TRUE(options->insert(s.option).second) << s.option << " twice";
        }
      },
      p);
  return keys;
}

template <class P>
void expect_written_as_declared(const Json& j, std::set<std::string>* options) {
  std::vector<std::string> written;
  for (auto it = j.begin(); it != j.end(); ++it) written.push_back(it.key());
  EXPECT_EQ(written, declared_keys<P>(options));
}

TEST(Commands, ManufacturingParametersAreWrittenAndCheckedAsDeclared) {
  std::set<std::string> options;  // tabs and holes share the implant and autoplan subcommands
  TabParams tabs;
  tabs.positions = {{1, 2, 3}};
  tabs.midline = Plane{Eigen::Vector3d::UnitX(), 4.0};
  expect_written_as_declared<TabParams>(to_json(tabs), &options);
  PerforationParams holes;
  holes.added = {{5, 6, 7}};
  expect_written_as_declared<PerforationParams>(to_json(holes), &options);
  std::set<std::string> mould_options;
  expect_written_as_declared<MouldParams>(to_json(MouldParams{}), &mould_options);
  expect_written_as_declared<Material>(to_json(*material_preset("peek")), &options);
  expect_written_as_declared<ClearanceZone>(to_json(ClearanceZone{}), &options);
  for (const Material& m : material_presets()) EXPECT_EQ(material_problem(m), "") << m.name;
  EXPECT_EQ(to_json(material_from_json(ParamReader(to_json(*material_preset("titanium")), "t"))),
            to_json(*material_preset("titanium")));

  const TabParams tabs_back = tabs_from_json(ParamReader(to_json(tabs), "test"));
  EXPECT_EQ(to_json(tabs_back), to_json(tabs));
  EXPECT_EQ(to_json(perforations_from_json(ParamReader(to_json(holes), "test"))), to_json(holes));
  EXPECT_EQ(to_json(mould_from_json(ParamReader(to_json(MouldParams{}), "test"))),
            to_json(MouldParams{}));

  Json bad = to_json(MouldParams{});
  bad["vent_diameter_mm"] = 7.0;
  try {
    mould_from_json(ParamReader(bad, "plan.json"));
    ADD_FAILURE() << "a vent 7 mm wide was read";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("the mould's vent's diameter must be 1 to 6 mm (7 given)"),
              std::string::npos)
        << e.what();
  }
  Json not_a_list = to_json(holes);
  not_a_list["added"] = 3;
  EXPECT_THROW(perforations_from_json(ParamReader(not_a_list, "plan.json")), SessionError);
}

// The smoothing's and the implant's own parameters are declared as well: written as declared,
// and a session whose values are out of range (a smoothing of a billion rounds would never end)
// is refused by the reader naming the parameter, before anything is computed.
TEST(Commands, SmoothingAndShellParametersAreWrittenAndCheckedAsDeclared) {
  std::set<std::string> smooth_options, implant_options;
  expect_written_as_declared<SmoothParams>(params_to_json(SmoothParams{}), &smooth_options);
  EXPECT_EQ(smooth_options, (std::set<std::string>{"radius", "edge-weight", "iterations"}));
  const Json implant = params_to_json(ImplantParams{});
  Json own = Json::object();  // the scalar fields; the groups each declare their own
  for (auto it = implant.begin(); it != implant.end(); ++it)
    if (!it.value().is_object() && !it.value().is_array() && it.key() != "method" &&
        it.key() != "frame" && it.key() != "radial_center" && it.key() != "material")
      own[it.key()] = it.value();
  expect_written_as_declared<ImplantParams>(own, &implant_options);
  EXPECT_TRUE(implant_options.count("fit-to-bone"));
  EXPECT_TRUE(implant.at("thickness_mm").is_null()) << "unset: the bone's thickness";

  const auto refused = [](const auto& read, const std::string& words) {
    try {
      read();
      ADD_FAILURE() << "read: " << words;
    } catch (const SessionError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("plan.json"), std::string::npos) << e.what();
    }
  };
  Json smooth = params_to_json(SmoothParams{});
  smooth["iterations"] = 1000000000;
  refused(
      [&] {
        SmoothParams p;
        params_from_json(ParamReader(smooth, "plan.json"), p);
      },
      "the smoothing's iterations must be 1 to 100 (1,000,000,000 given)");
  Json shell = params_to_json(ImplantParams{});
  shell["resolution_mm"] = 0.01;
  refused(
      [&] {
        ImplantParams p;
        params_from_json(ParamReader(shell, "plan.json"), p);
      },
      "the implant's resolution must be 0.2 to 10 mm (0.01 given)");
  SmoothParams back;
  params_from_json(ParamReader(params_to_json(SmoothParams{3.5, 4.0, 7}), "plan.json"), back);
  EXPECT_EQ(params_to_json(back), params_to_json(SmoothParams{3.5, 4.0, 7}));
  // The build refuses the same values given directly, in the same words.
  ImplantParams coarse;
  coarse.resolution_mm = 12.0;
  const ImplantResult r = build_implant({}, nullptr, coarse);
  EXPECT_FALSE(r.usable());
  EXPECT_NE(r.message.find("the implant's resolution must be 0.2 to 10 mm (12 given)"),
            std::string::npos)
      << r.message;
}

// The plane fit's and the registration's parameters too: written as declared (the starting
// transform and the region after the registration's), and a count out of range in a session is
// refused naming it rather than clamped without a word.
TEST(Commands, PlaneAndRegistrationParametersAreWrittenAndCheckedAsDeclared) {
  std::set<std::string> none;
  expect_written_as_declared<PlaneFitParams>(params_to_json(PlaneFitParams{}), &none);
  Json reg = params_to_json(RegisterParams{});
  EXPECT_TRUE(reg.contains("initial") && reg.contains("roi"));
  reg.erase("initial");
  reg.erase("roi");
  expect_written_as_declared<RegisterParams>(reg, &none);
  EXPECT_TRUE(none.empty()) << "no CLI option declared yet";

  Json plane = params_to_json(PlaneFitParams{});
  plane["outer_iterations"] = 5000;
  try {
    PlaneFitParams p;
    params_from_json(ParamReader(plane, "plan.json"), p);
    ADD_FAILURE() << "5,000 updates were read";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "the plane fit's number of updates must be 1 to 50 (5000 given)"),
              std::string::npos)
        << e.what();
  }
  Json trimmed = params_to_json(RegisterParams{});
  trimmed["trim_fraction"] = 0.0;
  try {
    RegisterParams p;
    params_from_json(ParamReader(trimmed, "plan.json"), p);
    ADD_FAILURE() << "a registration keeping no pair was read";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "the registration's share of pairs kept must be 0.05 to 1 (0 given)"),
              std::string::npos)
        << e.what();
  }
}

// A mesh's length unit is part of the load: recorded, replayed, and read as millimetres from
// a load_skull 1 or 2, which had none (nor turned a skull that winds inward outward). A unit that
// is no length is refused.
TEST(Commands, TheLoadRecordsTheMeshesLengthUnit) {
  test::TempDir dir;
  const std::string p = dir.path("head-m.stl");
  write_mesh(test::scaled(test::make_symmetric_head(3), 1e-3), p);

  Session refused;
  try {
    refused.push(commands::load_skull(p));
    ADD_FAILURE() << "a head in metres was loaded as millimetres";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("looks to be in metres"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(refused.state().skull);

  ExtractBoneSurfaceParams metres;
  metres.mesh_unit_mm = 1000.0;
  Session s;
  push_ok(s, commands::load_skull(p, metres));
  ASSERT_TRUE(s.state().skull);
  const MeshReport size = report_mesh(s.state().skull->surface->loaded.mesh);
  EXPECT_GT((size.bbox_max - size.bbox_min).maxCoeff(), 100.0) << "read in mm, not metres";
  const Json load = to_json(s.effective_commands().front());
  EXPECT_EQ(load["params"]["import"]["mesh_unit_mm"], 1000.0);
  const std::string saved = dir.path("plan.json");
  s.save(saved);
  const Session back = Session::open(saved);
  ASSERT_TRUE(back.state().skull);
  EXPECT_LT((back.state().skull->centroid - s.state().skull->centroid).norm(), 1e-9);

  ExtractBoneSurfaceParams import;
  Json old_load = load["params"]["import"];
  old_load.erase("mesh_unit_mm");
  old_load.erase("orient_outward");
  old_load.erase("orient_consistently");
  old_load.erase("drop_repeated_triangles");
  old_load.erase("close_holes_mm");
  old_load.erase("close_holes_through_corners");
  params_from_json(ParamReader(old_load, "test"), import);
  EXPECT_EQ(import.mesh_unit_mm, 1.0);
  EXPECT_FALSE(import.orient_outward) << "load_skull 2 read the skull as it came";
  EXPECT_FALSE(import.orient_consistently) << "load_skull 4 read its patches as they came";
  EXPECT_FALSE(import.drop_repeated_triangles) << "and kept every triangle";
  EXPECT_EQ(import.close_holes_mm, 0.0) << "and left every hole open";
  EXPECT_FALSE(import.close_holes_through_corners) << "load_skull 5 left holes touching open";
  EXPECT_EQ(load["params"]["import"]["close_holes_mm"], 15.0);
  EXPECT_EQ(load["params"]["import"]["drop_repeated_triangles"], true);
  EXPECT_EQ(load["params"]["import"]["orient_outward"], true);
  EXPECT_EQ(load["params"]["import"]["orient_consistently"], true);
  EXPECT_EQ(load["params"]["import"]["close_holes_through_corners"], true);
  EXPECT_EQ(load["version"], 6);
  // The reader's warnings reach the load's message (the wizard's status bar): here a head whose
  // triangles wind inward, turned outward.
  TriangleSoup inward = to_soup(test::make_symmetric_head(3));
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  write_mesh(build_mesh(inward), dir.path("inward.stl"));
  Session turned;
  push_ok(turned, commands::load_skull(dir.path("inward.stl")));
  EXPECT_NE(turned.state().message.find("inward.stl: the surface was inside out"),
            std::string::npos)
      << turned.state().message;
  for (const Json& bad : {Json(0.0), Json(-25.4), Json("m")}) {
    Json j = load["params"]["import"];
    j["mesh_unit_mm"] = bad;
    EXPECT_THROW(params_from_json(ParamReader(j, "test"), import), SessionError) << bad;
  }
}

// What the skull's file held and what the reading did about it is recorded in the load when it
// is first done ("input_report": triangles, pieces dropped, the warnings without the file's
// path): a skull left open, the opening said and how its inside is taken. A
// replay repairs the same way (the import's parameters are in the command) and says so when the
// file reads otherwise than recorded.
TEST(Commands, TheLoadRecordsWhatTheSkullHeldAndAReplaySaysWhenItDiffers) {
  test::TempDir dir;
  const SkullMesh head = test::make_symmetric_head(3);
  const MeshReport whole = report_mesh(head);
  const std::string p = dir.path("open.stl");
  write_mesh(
      test::cut_open(head, whole.bbox_min + Eigen::Vector3d(0, 0, 20), Eigen::Vector3d::UnitZ()),
      p);
  Session s;
  push_ok(s, commands::load_skull(p));
  const Json load = to_json(s.effective_commands().front());
  ASSERT_TRUE(load["params"].contains("input_report")) << load.dump();
  const Json& report = load["params"]["input_report"];
  EXPECT_EQ(report["triangles"], static_cast<long long>(s.state().skull->surface->mesh.n_faces()));
  EXPECT_EQ(report["pieces_dropped"], 0);
  bool says_open = false;
  for (const Json& w : report["warnings"]) {
    says_open = says_open || w.get<std::string>().find("open edge") != std::string::npos;
    EXPECT_EQ(w.get<std::string>().find(p), std::string::npos) << "no path: " << w;
  }
  EXPECT_TRUE(says_open) << report.dump();

  // Replayed from its file: the same report, nothing said.
  const std::string saved = dir.path("plan.json");
  s.save(saved);
  const Session back = Session::open(saved);
  ASSERT_TRUE(back.state().skull);
  EXPECT_EQ(back.state().message.find("reads otherwise"), std::string::npos)
      << back.state().message;
  EXPECT_EQ(to_json(back.effective_commands().front())["params"]["input_report"], report);

  // A load whose record says otherwise (as a file read by an older program would): said.
  Command recorded = commands::load_skull(p);
  recorded.params["input_report"] = report;
  recorded.params["input_report"]["triangles"] = 12;
  Session t;
  push_ok(t, recorded);
  EXPECT_NE(t.state().message.find("the file reads otherwise than when this plan was made"),
            std::string::npos)
      << t.state().message;
}

// Tabs and holes of plans saved before build_implant 8 are meshed as they were (without the
// gap kept around the iso-level), today's with it.
TEST(Commands, OlderBuildsMeshTheirTabsAndHolesAsTheyWereMade) {
  const Session planned = Session::open(test::planned_defect_case().session_path);
  const Json today = to_json(commands::build_implant(ImplantParams{}));
  Json older = today;
  older["version"] = 7;
  for (const auto& [json, gap] : {std::pair{today, true}, std::pair{older, false}}) {
    const ApplyOutcome out = apply_command(planned.state(), command_from_json(json, "test"));
    ASSERT_TRUE(out.state.implant_params.has_value()) << out.message;
    EXPECT_EQ(out.state.implant_params->tabs.iso_gap, gap);
    EXPECT_EQ(out.state.implant_params->perforations.iso_gap, gap);
  }
}

// Plans saved before build_implant 11 take their rims out to where the bone is first found and
// mesh the fit as its field comes, as they were fitted; today's go on until the rim has crossed
// the bone's surface and keep the field off the iso-level. Plans saved before build_implant 12
// place their tabs once and drill every pattern hole; today's place a tab off the bone again
// and leave out a hole whose rim would be too thin. Plans saved before build_implant 13 keep
// the fit's margin as asked; today's try others where the edge stands off the bone.
TEST(Commands, OlderBuildsTakeTheirRimsOutAsTheyWereMade) {
  const Session planned = Session::open(test::planned_defect_case().session_path);
  const Json today = to_json(commands::build_implant(ImplantParams{}));
  EXPECT_EQ(today["version"], 14);
  for (const auto& [version, reaches, keeps, searches, thick] :
       {std::tuple{14, true, true, true, true}, std::tuple{13, true, true, true, false},
        std::tuple{12, true, true, false, false}, std::tuple{11, true, false, false, false},
        std::tuple{10, false, false, false, false}}) {
    SCOPED_TRACE(version);
    Json json = today;
    json["version"] = version;
    const ApplyOutcome out = apply_command(planned.state(), command_from_json(json, "test"));
    ASSERT_TRUE(out.state.implant_params.has_value()) << out.message;
    EXPECT_EQ(out.state.implant_params->fit_keeps_shell_thick, thick);
    EXPECT_EQ(out.state.implant_params->fit_margin_search, searches);
    EXPECT_EQ(out.state.implant_params->fit_reaches_the_bone, reaches);
    EXPECT_EQ(out.state.implant_params->trim.iso_gap, reaches);
    EXPECT_EQ(out.state.implant_params->tabs.keep_on_bone, keeps);
    EXPECT_EQ(out.state.implant_params->perforations.sound_rims, keeps);
  }
}

// A mould exported before export_implant 2 is made again as it was meshed then (without the
// gap), today's with it: the replayed bytes are those of each meshing.
TEST(Commands, AnOlderMouldExportIsMadeAsItWasMeshed) {
  const Session planned = Session::open(test::planned_defect_case().session_path);
  MouldParams mould;
  mould.voxel_mm = 0.4;  // coarser than the default, for the test's time
  const Json today = to_json(commands::export_implant(test::scratch_path("m.3mf"), "", mould));
  EXPECT_EQ(today["version"], 2);
  Json older = today;
  older["version"] = 1;
  std::string replayed[2];
  for (int v : {1, 2}) {
    const ApplyOutcome out =
        apply_command(planned.state(), command_from_json(v == 1 ? older : today, "test"));
    ASSERT_TRUE(out.accepted) << out.message;
    replayed[v - 1] = out.state.exports.back().replayed_sha256;
  }
  ExportSpec spec;
  spec.format = "3mf";
  spec.mould = mould;
  spec.mould->iso_gap = false;
  std::string why;
  EXPECT_EQ(replayed[0], sha256_hex(export_bytes(planned.state(), spec, &why))) << why;
  EXPECT_NE(replayed[0], replayed[1]) << "the meshing without the gap differs on this mould";
}

// build_implant 4 holds the implant a set clearance off the bone's surface and removes thin
// fills; a version-3 command ("trim" without either) is read as it was fitted then, and a bad
// clearance is named.
TEST(Commands, BuildImplant3FitsTheBoneAsItWasMadeTo) {
  ImplantParams p;
  p.trim.clearance_mm = 0.25;
  const Json build = to_json(commands::build_implant(p));
  ImplantParams back;
  params_from_json(ParamReader(build["params"]["params"], "test"), back);
  ASSERT_TRUE(back.trim.clearance_mm.has_value());
  EXPECT_EQ(*back.trim.clearance_mm, 0.25);
  EXPECT_TRUE(back.trim.thin_fills_removed);
  EXPECT_EQ(ImplantParams{}.trim.clearance_mm, 0.1) << "today's default";

  Json unset = build["params"]["params"];
  unset["trim"]["clearance_mm"] = nullptr;
  unset["trim"]["thin_fills_removed"] = false;
  params_from_json(ParamReader(unset, "test"), back);
  EXPECT_FALSE(back.trim.clearance_mm.has_value()) << "recorded as unset, read as unset";
  EXPECT_FALSE(back.trim.thin_fills_removed);

  Json session9 = build["params"]["params"];
  session9["trim"].erase("clearance_mm");
  session9["trim"].erase("thin_fills_removed");
  back = ImplantParams{};
  params_from_json(ParamReader(session9, "test"), back);
  EXPECT_FALSE(back.trim.clearance_mm.has_value());
  EXPECT_FALSE(back.trim.thin_fills_removed);
  EXPECT_EQ(back.trim.min_feature_mm, 1.5) << "the rest as recorded";

  Json bad = build["params"]["params"];
  bad["trim"]["clearance_mm"] = -0.5;
  try {
    params_from_json(ParamReader(bad, "plan.json command 7"), back);
    ADD_FAILURE() << "a negative clearance is accepted";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("clearance_mm"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("plan.json command 7"), std::string::npos) << e.what();
  }
}

// propose_markers 2 records how the surfaces are fitted and which opening was asked for; a
// version-1 command (neither) is read with their defaults. Version 4 records how far support
// markers may lie from the fitted surfaces; older ones are read without that rule. Version 5
// records the footprint the mirror is read over; older ones read it along one ray. Version 6
// records whether fitting sites of few rays are smoothed more; older ones weigh all alike.
TEST(Commands, ProposeMarkersVersionTwoRoundTripsAndVersionOneGetsDefaults) {
  ProposeParams p;
  p.surfaces.ring_width_mm = 31.0;
  p.surfaces.smoothing = 0.07;
  p.detect.near = Eigen::Vector3d(1.5, -2.0, 70.25);
  p.max_support_off_fit_mm = 2.25;
  p.surfaces.mirror_footprint_mm = 2.5;
  p.detect.trace_from_area_mm2 = 2500.0;
  const Json j = to_json(commands::propose_markers(p));
  EXPECT_EQ(j["version"], 8);
  EXPECT_TRUE(p.surfaces.weigh_sites_by_rays) << "the default";
  EXPECT_EQ(j["params"]["params"]["surfaces"]["weigh_sites_by_rays"], true);
  ProposeParams back;
  params_from_json(ParamReader(j["params"]["params"], "test"), back);
  EXPECT_EQ(back.surfaces.ring_width_mm, 31.0);
  EXPECT_EQ(back.surfaces.smoothing, 0.07);
  EXPECT_EQ(back.max_support_off_fit_mm, 2.25);
  EXPECT_EQ(back.surfaces.mirror_footprint_mm, 2.5);
  EXPECT_TRUE(back.surfaces.weigh_sites_by_rays);
  ProposeParams alike;
  alike.surfaces.weigh_sites_by_rays = false;
  ProposeParams alike_back;
  params_from_json(
      ParamReader(to_json(commands::propose_markers(alike))["params"]["params"], "test"),
      alike_back);
  EXPECT_FALSE(alike_back.surfaces.weigh_sites_by_rays);
  ASSERT_TRUE(back.detect.near.has_value());
  EXPECT_EQ(*back.detect.near, *p.detect.near);
  EXPECT_FALSE(j["params"]["params"]["detect"].contains("center")) << "unset: not written";
  // Where the rays start, when a caller sets it, is recorded and read back.
  ProposeParams moved;
  moved.detect.center = Eigen::Vector3d(3.0, -1.25, 60.5);
  ProposeParams moved_back;
  params_from_json(
      ParamReader(to_json(commands::propose_markers(moved))["params"]["params"], "test"),
      moved_back);
  ASSERT_TRUE(moved_back.detect.center.has_value());
  EXPECT_EQ(*moved_back.detect.center, *moved.detect.center);

  Json v1 = j;
  v1["version"] = 1;
  v1["params"]["params"].erase("surfaces");
  v1["params"]["params"]["detect"].erase("near");
  v1["params"]["params"].erase("max_support_off_fit_mm");
  const Command c = command_from_json(v1, "old plan");
  EXPECT_EQ(c.version, 1);
  ProposeParams old;
  params_from_json(ParamReader(c.params["params"], "test"), old);
  EXPECT_FALSE(old.detect.near.has_value());
  EXPECT_EQ(old.surfaces.ring_width_mm, DefectSurfaceParams{}.ring_width_mm);
  // Before version 4 support markers stood on every ring point of the band.
  EXPECT_EQ(old.max_support_off_fit_mm, 0.0);
  EXPECT_EQ(old.surfaces.mirror_footprint_mm, 0.0);
  EXPECT_FALSE(old.surfaces.weigh_sites_by_rays);
  // Version 4 has the surfaces but no footprint: the mirror along one ray.
  Json v4 = j;
  v4["version"] = 4;
  v4["params"]["params"]["surfaces"].erase("mirror_footprint_mm");
  v4["params"]["params"]["surfaces"].erase("weigh_sites_by_rays");
  ProposeParams four;
  params_from_json(ParamReader(command_from_json(v4, "old plan").params["params"], "test"), four);
  EXPECT_EQ(four.surfaces.ring_width_mm, 31.0);
  EXPECT_EQ(four.surfaces.mirror_footprint_mm, 0.0);
  EXPECT_FALSE(four.surfaces.weigh_sites_by_rays);
  // Version 5 has the footprint but weighs every site alike.
  Json v5 = j;
  v5["version"] = 5;
  v5["params"]["params"]["surfaces"].erase("weigh_sites_by_rays");
  ProposeParams five;
  params_from_json(ParamReader(command_from_json(v5, "old plan").params["params"], "test"), five);
  EXPECT_EQ(five.surfaces.mirror_footprint_mm, 2.5);
  EXPECT_FALSE(five.surfaces.weigh_sites_by_rays);
  // Version 7 traces the rim on the bone, with its limits recorded.
  EXPECT_TRUE(back.detect.trace_rim_on_bone);
  EXPECT_EQ(back.detect.trace_from_area_mm2, 2500.0);
  EXPECT_EQ(back.detect.trace_from_unseen_mm, DetectDefectParams{}.trace_from_unseen_mm);
  Json v6 = j;
  v6["version"] = 6;
  for (const char* key : {"trace_rim_on_bone", "trace_from_area_mm2", "trace_from_unseen_mm"})
    v6["params"]["params"]["detect"].erase(key);
  ProposeParams six;
  params_from_json(ParamReader(command_from_json(v6, "old plan").params["params"], "test"), six);
  EXPECT_FALSE(six.detect.trace_rim_on_bone);
  EXPECT_EQ(back.max_support_layers, ProposeParams{}.max_support_layers);
  v6["params"]["params"].erase("max_support_layers");
  params_from_json(ParamReader(command_from_json(v6, "old plan").params["params"], "test"), six);
  EXPECT_EQ(six.max_support_layers, 0.0) << "before version 7: no limit";
}

TEST(Commands, UnknownTypeVersionAndMissingParameterAreNamed) {
  Json j = to_json(commands::smooth_markers({8, 2, 1}));
  Json unknown = j;
  unknown["type"] = "paint_skull";
  EXPECT_THROW(
      {
        try {
          command_from_json(unknown, "plan.json: commands[4]");
        } catch (const SessionError& e) {
          EXPECT_NE(std::string(e.what()).find("plan.json: commands[4]"), std::string::npos);
          EXPECT_NE(std::string(e.what()).find("unknown command type \"paint_skull\""),
                    std::string::npos);
          throw;
        }
      },
      SessionError);
  Json newer = j;
  newer["version"] = 7;
  EXPECT_THROW(command_from_json(newer, "x"), SessionError);
  Json missing = j;
  missing["params"].erase("project_onto_mirror");
  try {
    command_from_json(missing, "plan.json: commands[4]");
    ADD_FAILURE() << "missing parameter accepted";
  } catch (const SessionError& e) {
    EXPECT_NE(std::string(e.what()).find("missing parameter 'project_onto_mirror'"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace cranioplan
