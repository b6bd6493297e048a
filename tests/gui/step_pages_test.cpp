// Each wizard page on its own, with a host that records what the page asks for: the commands
// its controls push, how it reads clicks on the skull, what it shows of a state.
#include "pages/step_pages.h"

#include <gtest/gtest.h>

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QLabel>
#include <QPushButton>
#include <QSettings>
#include <QSlider>
#include <QTest>
#include <QTextBrowser>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>

#include "cranioplan/algorithms/planning/autoplan.h"
#include "cranioplan/sessions/sha256.h"

namespace cranioplan::gui {
namespace {

class RecordingHost : public PageHost {
 public:
  const PlanState& plan() const override { return state; }
  void push(Command command, const QString& what) override {
    pushed.push_back(std::move(command));
    announced.push_back(what);
  }
  void show_message(const QString& text, bool) override { messages.push_back(text); }
  SkullView& view() override { return view_; }
  MarkerType marker_type() const override { return type; }
  void set_marker_type(MarkerType t) override { type = t; }
  void open_skull(const QString& path) override { opened.push_back(path); }
  void open_sample() override { opened.push_back("sample"); }
  bool export_to(const QString& path, bool) override {
    opened.push_back(path);
    return true;
  }
  void import_markers(const QString& path) override { opened.push_back(path); }
  void show_slices() override { opened.push_back("slices"); }
  void show_mould(bool shown) override { opened.push_back(shown ? "mould" : "no mould"); }
  QString suggested_path(const QString& file_name) const override { return file_name; }
  std::shared_ptr<const PlanState> preview(const Command& command) override {
    previewed.push_back(command);
    return nullptr;
  }

  PlanState state;
  MarkerType type = MarkerType::OuterEdge;
  std::vector<Command> pushed, previewed;
  std::vector<QString> announced, messages, opened;

 private:
  SkullView view_;
};

template <class T>
T* child(QWidget& page, const char* name) {
  T* c = page.findChild<T*>(name);
  EXPECT_NE(c, nullptr) << "no " << name;
  return c;
}

void click(QWidget& page, const char* name) {
  QPushButton* b = child<QPushButton>(page, name);
  ASSERT_TRUE(b);
  QTest::mouseClick(b, Qt::LeftButton);
}

TEST(StepPages, EveryStepHasItsPageInOrder) {
  RecordingHost host;
  for (int step = 1; step <= 9; ++step) {
    const std::unique_ptr<StepPage> page = make_step_page(step, host);
    ASSERT_TRUE(page) << "step " << step;
    EXPECT_EQ(page->step(), step);
    // The instructions name the step and say what is left to do on an empty plan.
    const QString html = page->instructions_html(host.state);
    EXPECT_TRUE(html.contains(QString::fromLatin1(wizard_steps()[step - 1].title))) << step;
    EXPECT_TRUE(html.contains("To do")) << step;
  }
  EXPECT_FALSE(make_step_page(0, host));
  EXPECT_FALSE(make_step_page(10, host));
}

TEST(StepPages, ClicksPlaceTheThreeLandmarksInTurn) {
  RecordingHost host;
  PlanePage page(host);
  EXPECT_EQ(page.pick_target(), SkullView::PickTarget::Original);
  for (int i = 0; i < 4; ++i) page.surface_clicked(Eigen::Vector3d(i, 0, 0));
  ASSERT_EQ(host.pushed.size(), 4u);
  // After the three, a click adds a midline point (it does not move the right orbit's).
  const char* expected[] = {"nasion", "orbit_left", "orbit_right", "midline"};
  for (int i = 0; i < 4; ++i) {
    EXPECT_EQ(host.pushed[i].type, CommandType::SetLandmark);
    EXPECT_EQ(host.pushed[i].params.at("name"), expected[i]) << i;
  }
  click(page, "fitPlane");
  EXPECT_EQ(host.pushed.back().type, CommandType::FitPlane);
  EXPECT_FALSE(host.announced.back().isEmpty()) << "a long command is announced";
  click(page, "clearLandmarks");
  EXPECT_EQ(host.pushed.back().type, CommandType::ClearLandmark);
}

TEST(StepPages, ARegistrationAroundAClickedPointCarriesItsRegion) {
  RecordingHost host;
  MirrorPage page(host);
  click(page, "register");
  ASSERT_EQ(host.pushed.back().type, CommandType::Register);
  const Json whole = host.pushed.back().params;
  page.surface_clicked(Eigen::Vector3d(10, 20, 30));
  EXPECT_TRUE(child<QCheckBox>(page, "roiOnly")->isChecked());
  click(page, "register");
  const Json around = host.pushed.back().params;
  EXPECT_NE(whole, around);
  EXPECT_NE(around.dump().find("30"), std::string::npos) << around.dump();
}

TEST(StepPages, TheClipPlaneIsACommandAndFollowsTheState) {
  RecordingHost host;
  ClipPage page(host);
  auto* on = child<QCheckBox>(page, "clipOn");
  on->setChecked(true);
  ASSERT_EQ(host.pushed.size(), 1u);
  EXPECT_EQ(host.pushed[0].type, CommandType::SetClipPlane);
  on->setChecked(false);
  EXPECT_EQ(host.pushed.back().type, CommandType::SetClipPlane);
  // Showing a state sets the box without pushing anything.
  host.state.clip_plane = Plane::through(Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX());
  page.show_state(host.state);
  EXPECT_TRUE(on->isChecked());
  EXPECT_EQ(host.pushed.size(), 2u);
}

// Stretches of the rim no ray saw: the view draws one orange line for each, and the edge page
// says what they mean; a proposal without them shows neither.
TEST(StepPages, TheEdgePageAndTheViewShowTheRimsUnseenStretches) {
  RecordingHost host;
  EdgeMarkersPage edges(host);
  host.state.proposal_message = "161 markers proposed";
  host.state.unseen_rim = {{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(13, 0, 0)},
                           {Eigen::Vector3d(0, 5, 0), Eigen::Vector3d(0, 17, 0)}};
  edges.show_state(host.state);
  host.view().show_state(host.state);
  const QLabel* note = child<QLabel>(edges, "proposalNote");
  ASSERT_TRUE(note);
  EXPECT_TRUE(note->text().contains("orange lines")) << note->text().toStdString();
  EXPECT_EQ(host.view().unseen_rim_shown(), 2);
  host.state.unseen_rim.clear();
  edges.show_state(host.state);
  host.view().show_state(host.state);
  EXPECT_FALSE(note->text().contains("orange lines")) << note->text().toStdString();
  EXPECT_TRUE(note->text().contains("161 markers proposed"));
  EXPECT_EQ(host.view().unseen_rim_shown(), 0);
}

TEST(StepPages, MarkersGoOnTheSurfaceTheirTypeBelongsTo) {
  RecordingHost host;
  EdgeMarkersPage edges(host);
  SurfaceMarkersPage surfaces(host);
  EXPECT_TRUE(edges.markers_editable());
  click(surfaces, "markerType3");
  EXPECT_EQ(host.type, MarkerType::InnerSurface);
  EXPECT_EQ(edges.pick_target(), SkullView::PickTarget::Mirrored);
  click(edges, "markerType1");
  EXPECT_EQ(host.type, MarkerType::InnerEdge);
  EXPECT_EQ(surfaces.pick_target(), SkullView::PickTarget::Original);
  surfaces.surface_clicked(Eigen::Vector3d(1, 2, 3));
  ASSERT_EQ(host.pushed.back().type, CommandType::AddMarker);
  EXPECT_EQ(host.pushed.back().params.at("type"), static_cast<int>(MarkerType::InnerEdge));
  click(edges, "propose");
  EXPECT_EQ(host.pushed.back().type, CommandType::ProposeMarkers);
  click(edges, "clearMarkers");
  EXPECT_EQ(host.pushed.back().type, CommandType::ClearMarkers);
}

// The proposal can be guided by a model of the normal skull: the choice (the box and the file)
// is remembered in the settings, and a proposal made with it ticked names the model, with its
// SHA-256, in the command; unticked it names none.
TEST(StepPages, AProposalGuidedByAShapeModelNamesItInTheCommand) {
  const auto model = std::filesystem::temp_directory_path() / "cranioplan_gui_model.cpsm";
  std::ofstream(model) << "CRANIOPLAN-SHAPE-MODEL 1\n";
  QSettings().setValue("shapeModel/path", QString::fromStdString(model.string()));
  QSettings().setValue("shapeModel/use", false);
  RecordingHost host;
  EdgeMarkersPage page(host);
  auto* use = child<QCheckBox>(page, "useShapeModel");
  EXPECT_FALSE(use->isChecked());
  EXPECT_EQ(child<QLabel>(page, "shapeModelFile")->text(), "cranioplan_gui_model.cpsm");
  click(page, "propose");
  ASSERT_EQ(host.pushed.back().type, CommandType::ProposeMarkers);
  EXPECT_FALSE(host.pushed.back().params.contains("shape_model"));
  use->setChecked(true);
  EXPECT_TRUE(QSettings().value("shapeModel/use").toBool());
  click(page, "propose");
  ASSERT_EQ(host.pushed.back().type, CommandType::ProposeMarkers);
  EXPECT_EQ(host.pushed.back().params["shape_model"]["path"], model.string());
  EXPECT_EQ(host.pushed.back().params["shape_model"]["sha256"], sha256_file(model.string()));
  // Remembered: a new page (the next plan) starts ticked with the same file.
  EdgeMarkersPage next(host);
  EXPECT_TRUE(child<QCheckBox>(next, "useShapeModel")->isChecked());
  QSettings().setValue("shapeModel/use", false);
  std::filesystem::remove(model);
}

// A reopened plan shows the model its last proposal was guided by, whatever the settings say,
// and proposes again with it; the settings keep the user's own choice. A proposal without a
// model unticks the box; the user's change after a proposal stays; a plan without a proposal
// shows the settings' choice.
TEST(StepPages, AReopenedPlanShowsTheModelItsProposalUsed) {
  const auto model = std::filesystem::temp_directory_path() / "cranioplan_plan_model.cpsm";
  std::ofstream(model) << "CRANIOPLAN-SHAPE-MODEL 1\n";
  QSettings().setValue("shapeModel/path", QString("/elsewhere/settings_model.cpsm"));
  QSettings().setValue("shapeModel/use", false);
  RecordingHost host;
  EdgeMarkersPage page(host);
  auto* use = child<QCheckBox>(page, "useShapeModel");
  EXPECT_FALSE(use->isChecked());
  host.state.proposal_message = "12 markers proposed; guided by the shape model";
  host.state.proposal_shape_model = model.string();
  page.show_state(host.state);
  EXPECT_TRUE(use->isChecked());
  EXPECT_EQ(child<QLabel>(page, "shapeModelFile")->text(), "cranioplan_plan_model.cpsm");
  EXPECT_FALSE(QSettings().value("shapeModel/use").toBool());
  // Proposed again as the plan's proposal was asked: its model's weight and fit as recorded.
  host.state.proposal_params.shape_model_weight = 1.0;
  host.state.proposal_params.surface_spacing_mm = 5.0;
  host.state.proposal_prior.margin_mm = 15.0;
  host.state.proposal_prior.fit.max_rms_mm = 0.8;
  click(page, "propose");
  ASSERT_EQ(host.pushed.back().type, CommandType::ProposeMarkers);
  const Json& asked = host.pushed.back().params;
  EXPECT_EQ(asked["shape_model"]["path"], model.string());
  EXPECT_EQ(asked["shape_model"]["weight"], 1.0);
  EXPECT_EQ(asked["shape_model"]["margin_mm"], 15.0);
  EXPECT_EQ(asked["shape_model"]["max_rms_mm"], 0.8);
  EXPECT_EQ(asked["params"]["surface_spacing_mm"], 5.0);
  // Unticked by the user: the same proposal shown again leaves it so.
  use->setChecked(false);
  page.show_state(host.state);
  EXPECT_FALSE(use->isChecked());
  // A new proposal without a model: unticked, the settings' file named.
  use->setChecked(true);
  host.state.proposal_message = "10 markers proposed";
  host.state.proposal_shape_model.clear();
  page.show_state(host.state);
  EXPECT_FALSE(use->isChecked());
  EXPECT_EQ(child<QLabel>(page, "shapeModelFile")->text(), "settings_model.cpsm");
  // Back to a plan guided by the model, then a new plan (no proposal yet): the settings' choice
  // again (here unticked), not the last plan's model.
  host.state.proposal_message = "12 markers proposed; guided by the shape model";
  host.state.proposal_shape_model = model.string();
  page.show_state(host.state);
  EXPECT_TRUE(use->isChecked());
  QSettings().setValue("shapeModel/use", false);
  host.state.proposal_message.clear();
  host.state.proposal_shape_model.clear();
  page.show_state(host.state);
  EXPECT_FALSE(use->isChecked());
  EXPECT_EQ(child<QLabel>(page, "shapeModelFile")->text(), "settings_model.cpsm");
  QSettings().setValue("shapeModel/use", false);
  QSettings().remove("shapeModel/path");
  std::filesystem::remove(model);
}

TEST(StepPages, TheMarkerCountsAndTheProposalNoteShowTheState) {
  RecordingHost host;
  EdgeMarkersPage page(host);
  for (int i = 0; i < 3; ++i) host.state.markers.push_back(Marker{i, MarkerType::OuterEdge, {}});
  host.state.markers.push_back(Marker{3, MarkerType::OuterSurface, {}});
  host.state.proposal_message = "12 markers proposed";
  page.show_state(host.state);
  bool counted = false;
  for (QLabel* label : page.findChildren<QLabel*>())
    counted |= label->text() == "Outer edge: 3, inner edge: 0";
  EXPECT_TRUE(counted);
  auto* note = child<QLabel>(page, "proposalNote");
  EXPECT_TRUE(note->text().contains("12 markers proposed"));
  host.state.proposal_message.clear();
  page.show_state(host.state);
  EXPECT_TRUE(note->isHidden());
}

TEST(StepPages, BuildPushesTheParametersTheControlsShow) {
  RecordingHost host;
  BuildPage page(host);
  ImplantParams built;
  built.method = ImplantMethod::Shell;
  built.resolution_mm = 0.8;
  built.thickness_mm = 3.5;
  built.fit_to_bone_mm = 4.0;
  host.state.implant_params = built;
  page.show_state(host.state);
  EXPECT_DOUBLE_EQ(child<QDoubleSpinBox>(page, "implantFit")->value(), 4.0);
  click(page, "build");
  ASSERT_EQ(host.pushed.back().type, CommandType::BuildImplant);
  const Json& p = host.pushed.back().params.at("params");
  EXPECT_DOUBLE_EQ(p.at("resolution_mm").get<double>(), 0.8);
  EXPECT_DOUBLE_EQ(p.at("thickness_mm").get<double>(), 3.5);
  EXPECT_DOUBLE_EQ(p.at("fit_to_bone_mm").get<double>(), 4.0);
}

// The shell's fields take the declared ranges: a plan made on the command line (fitted 10 mm
// over the bone, a 20 mm thickness, a 9 mm resolution) shows and rebuilds with its own values,
// not clamped ones; a field that may be left unset steps from unset straight to the least value
// allowed (a plate of 0.1 mm would be refused) and back.
TEST(StepPages, TheShellsFieldsTakeTheDeclaredRanges) {
  RecordingHost host;
  BuildPage page(host);
  ImplantParams built;
  built.resolution_mm = 9.0;
  built.thickness_mm = 20.0;
  built.fit_to_bone_mm = 10.0;
  host.state.implant_params = built;
  page.show_state(host.state);
  click(page, "build");
  ASSERT_EQ(host.pushed.back().type, CommandType::BuildImplant);
  const Json& p = host.pushed.back().params.at("params");
  EXPECT_DOUBLE_EQ(p.at("resolution_mm").get<double>(), 9.0);
  EXPECT_DOUBLE_EQ(p.at("thickness_mm").get<double>(), 20.0);
  EXPECT_DOUBLE_EQ(p.at("fit_to_bone_mm").get<double>(), 10.0);
  auto* plate = child<QDoubleSpinBox>(page, "materialPlate");
  ASSERT_EQ(plate->value(), 0.0);
  plate->stepUp();
  EXPECT_DOUBLE_EQ(plate->value(), spec_of<Material>("thickness_mm").min) << "unset, then 0.3 mm";
  plate->stepDown();
  EXPECT_DOUBLE_EQ(plate->value(), 0.0) << "back to unset";
  EXPECT_EQ(child<QDoubleSpinBox>(page, "implantResolution")->maximum(),
            spec_of<ImplantParams>("resolution_mm").max);
}

// An implant fitted from another margin than the one asked: the field keeps the margin asked,
// the panel says which one was used and why.
TEST(StepPages, AFitFromAnotherMarginIsSaid) {
  RecordingHost host;
  BuildPage page(host);
  ImplantParams asked;
  asked.fit_to_bone_mm = 4.0;
  host.state.implant_params = asked;
  ImplantResult built;
  built.status = ImplantResult::Status::Built;
  built.fit_to_bone_used_mm = 5.0;
  built.fit_margin_note =
      "built 5 mm over the bone instead of 4: at 4 mm its edge stood 1.07 mm off the bone at "
      "(100.0, 52.7, 80.5) mm";
  host.state.implant = std::make_shared<const ImplantData>(built, nullptr);
  page.show_state(host.state);
  EXPECT_DOUBLE_EQ(child<QDoubleSpinBox>(page, "implantFit")->value(), 4.0);
  QLabel* note = child<QLabel>(page, "fitNote");
  ASSERT_TRUE(note);
  EXPECT_FALSE(note->isHidden());
  EXPECT_EQ(note->text().toStdString(),
            "Built 5 mm over the bone instead of 4: at 4 mm its edge stood 1.07 mm off the bone "
            "at (100.0, 52.7, 80.5) mm.");
  // Fitted as asked: nothing said.
  built.fit_to_bone_used_mm = 4.0;
  built.fit_margin_note.clear();
  host.state.implant = std::make_shared<const ImplantData>(built, nullptr);
  page.show_state(host.state);
  EXPECT_TRUE(note->isHidden());
}

// A material chosen fills its values and is built with them (the fit to the bone turned on for
// its clearance); with "mark a wider clearance" on, a click on the rim adds a clearance zone
// and builds again; the zone is removed the same way. A plan built with a material shows it.
TEST(StepPages, TheMaterialAndClearanceZonesAreBuilt) {
  RecordingHost host;
  BuildPage page(host);
  host.state.implant_params = ImplantParams{};
  page.show_state(host.state);
  EXPECT_FALSE(child<QDoubleSpinBox>(page, "materialClearance")->isEnabled());
  child<QComboBox>(page, "implantMaterial")->setCurrentIndex(2);  // PMMA
  EXPECT_DOUBLE_EQ(child<QDoubleSpinBox>(page, "materialUnderContour")->value(), 0.5);
  EXPECT_DOUBLE_EQ(child<QDoubleSpinBox>(page, "implantFit")->value(), 4.0);
  child<QDoubleSpinBox>(page, "materialClearance")->setValue(1.5);
  click(page, "build");
  ASSERT_EQ(host.pushed.size(), 1u);
  const Json& built = host.pushed.back().params.at("params");
  EXPECT_EQ(built.at("material").at("name"), "PMMA");
  EXPECT_DOUBLE_EQ(built.at("material").at("edge_clearance_mm").get<double>(), 1.5);
  EXPECT_TRUE(built.at("clearance_zones").empty());

  EXPECT_EQ(page.pick_target(), SkullView::PickTarget::None) << "clicks do nothing until asked";
  page.surface_clicked(Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(host.pushed.size(), 1u);
  child<QPushButton>(page, "markZone")->setChecked(true);
  EXPECT_EQ(page.pick_target(), SkullView::PickTarget::Original);
  child<QDoubleSpinBox>(page, "zoneClearance")->setValue(2.5);
  page.surface_clicked(Eigen::Vector3d(1, 2, 3));
  ASSERT_EQ(host.pushed.size(), 2u);
  const Json& zoned = host.pushed.back().params.at("params");
  ASSERT_EQ(zoned.at("clearance_zones").size(), 1u);
  EXPECT_DOUBLE_EQ(zoned.at("clearance_zones")[0].at("clearance_mm").get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(zoned.at("clearance_zones")[0].at("radius_mm").get<double>(), 15.0);

  // The plan as it now stands (the zone built), shown; then the zone removed.
  ImplantParams now;
  params_from_json(ParamReader(zoned, "test"), now);
  host.state.implant_params = now;
  page.show_state(host.state);
  EXPECT_EQ(child<QComboBox>(page, "implantMaterial")->currentText(), "PMMA");
  EXPECT_DOUBLE_EQ(child<QDoubleSpinBox>(page, "materialClearance")->value(), 1.5);
  click(page, "removeZone");
  ASSERT_EQ(host.pushed.size(), 3u);
  EXPECT_TRUE(host.pushed.back().params.at("params").at("clearance_zones").empty());
}

// Step 7's defaults are the automatic plan's (fitted to the bone), its Build button comes
// first on the page, a control changed after a build says Build applies it, and the quality
// check's verdict shows on the page.
TEST(StepPages, BuildDefaultsToTheAutomaticPlansFitAndSaysWhatChanged) {
  RecordingHost host;
  BuildPage page(host);
  page.resize(360, 900);
  page.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&page));
  EXPECT_DOUBLE_EQ(child<QDoubleSpinBox>(page, "implantFit")->value(),
                   AutoplanParams{}.implant.fit_to_bone_mm);
  QPushButton* build = child<QPushButton>(page, "build");
  ASSERT_TRUE(build);
  for (QWidget* w : page.findChildren<QDoubleSpinBox*>())
    EXPECT_LT(build->mapTo(&page, QPoint()).y(), w->mapTo(&page, QPoint()).y())
        << "Build comes before " << w->objectName().toStdString();
  click(page, "build");
  ASSERT_EQ(host.pushed.size(), 1u);
  EXPECT_DOUBLE_EQ(host.pushed[0].params.at("params").at("fit_to_bone_mm").get<double>(), 4.0);

  // An implant built: a change says it is not applied yet; the next implant clears it.
  QLabel* changed = child<QLabel>(page, "buildChanged");
  host.state.implant_params = ImplantParams{};
  host.state.implant_params->fit_to_bone_mm = 4.0;
  ImplantResult built;
  built.status = ImplantResult::Status::Built;
  host.state.implant = std::make_shared<const ImplantData>(built, nullptr);
  page.show_state(host.state);
  EXPECT_TRUE(changed->isHidden()) << "showing the plan is not a change";
  page.show_verdict("<p>Not printable: the quality check refuses this implant.</p>");
  EXPECT_FALSE(child<QLabel>(page, "buildVerdict")->isHidden());
  child<QComboBox>(page, "implantMaterial")->setCurrentIndex(1);
  EXPECT_FALSE(changed->isHidden());
  EXPECT_FALSE(child<QLabel>(page, "buildVerdict")->isEnabled()) << "the old verdict greyed";
  host.state.implant = std::make_shared<const ImplantData>(built, nullptr);
  page.show_state(host.state);
  EXPECT_TRUE(changed->isHidden());
}

TEST(StepPages, SmoothingIsPreviewedThenApplied) {
  RecordingHost host;
  SmoothPage page(host);
  auto* radius = child<QSlider>(page, "smoothRadius");
  radius->setValue(15);
  EXPECT_TRUE(host.previewed.empty()) << "no preview without an implant";
  host.state.implant = std::make_shared<ImplantData>(ImplantResult{}, nullptr);
  radius->setValue(20);
  ASSERT_EQ(host.previewed.size(), 1u);
  EXPECT_EQ(host.previewed[0].type, CommandType::SmoothMarkers);
  EXPECT_TRUE(host.pushed.empty()) << "a preview records nothing";
  EXPECT_EQ(child<QLabel>(page, "smoothRadiusValue")->text(), "20 mm") << "value beside it";
  child<QSlider>(page, "smoothWeight")->setValue(5);
  EXPECT_EQ(child<QLabel>(page, "smoothWeightValue")->text(), "5");
  click(page, "applySmoothing");
  ASSERT_EQ(host.pushed.size(), 1u);
  EXPECT_EQ(host.pushed[0].params, host.previewed[1].params);
  bool applied = false;
  for (QLabel* l : page.findChildren<QLabel*>()) applied |= l->text().startsWith("Applied");
  EXPECT_TRUE(applied) << "after Apply the page says it was applied, not 'preview'";
}

// The export page shows the quality check's verdict; the table itself is the window's
// Quality panel, shown once.
TEST(StepPages, TheExportPageShowsTheQualityVerdict) {
  RecordingHost host;
  ExportPage page(host);
  page.show_verdict("<p>Printable: the quality check passes</p>");
  EXPECT_TRUE(child<QLabel>(page, "exportVerdict")->text().contains("Printable"));
  EXPECT_EQ(page.findChild<QTextBrowser*>(), nullptr) << "no second quality table";
}

TEST(StepPages, TheLoadPageKnowsTheMeshUnits) {
  RecordingHost host;
  LoadPage page(host);
  EXPECT_DOUBLE_EQ(page.mesh_unit_mm(), 1.0);
  EXPECT_TRUE(page.set_mesh_unit("cm"));
  EXPECT_DOUBLE_EQ(page.mesh_unit_mm(), 10.0);
  EXPECT_FALSE(page.set_mesh_unit("furlong"));
  EXPECT_DOUBLE_EQ(page.mesh_unit_mm(), 10.0);
  // The bone threshold is automatic by default (a CT at 300 HU, a mask at 0.5): a mask opens
  // with the default as a CT does.
  EXPECT_TRUE(std::isnan(page.threshold()));
  page.set_threshold(250.0);
  EXPECT_DOUBLE_EQ(page.threshold(), 250.0);
  page.set_threshold(std::numeric_limits<double>::quiet_NaN());
  EXPECT_TRUE(std::isnan(page.threshold()));
  click(page, "pageSample");
  ASSERT_EQ(host.opened.size(), 1u);
  EXPECT_EQ(host.opened[0], "sample");
}

}  // namespace
}  // namespace cranioplan::gui
