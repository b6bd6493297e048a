#include <QCheckBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QLabel>
#include <QPushButton>
#include <QSettings>
#include <QSignalBlocker>

#include "cranioplan/model/error.h"
#include "step_pages.h"

namespace cranioplan::gui {

namespace {

QString marker_type_label(MarkerType type) {
  return QString::fromStdString(to_string(type)).replace('_', ' ');
}

}  // namespace

MarkersPage::MarkersPage(int step, PageHost& host, MarkerType first, MarkerType second)
    : StepPage(step, host), first_(first), second_(second) {
  // One checkable button per type, named markerType0–3 (the window checks the one keys choose).
  for (MarkerType type : {first, second}) {
    const int t = static_cast<int>(type);
    auto* b = new QPushButton(QStringLiteral("[%1] %2").arg(t).arg(marker_type_label(type)), this);
    b->setObjectName(QStringLiteral("markerType%1").arg(t));
    b->setCheckable(true);
    b->setAutoExclusive(true);
    connect(b, &QPushButton::clicked, this, [this, type] { host_.set_marker_type(type); });
    form_->addRow(b);
  }
}

void MarkersPage::add_counts_row() {
  counts_ = new QLabel(this);
  form_->addRow(counts_);
}

void MarkersPage::show_state(const PlanState& s) {
  int counts[4] = {0, 0, 0, 0};
  for (const auto& m : s.markers) ++counts[static_cast<int>(m.type)];
  const auto capitalised = [](QString s) {
    s[0] = s[0].toUpper();
    return s;
  };
  counts_->setText(tr("%1: %2, %3: %4")
                       .arg(capitalised(marker_type_label(first_)))
                       .arg(counts[static_cast<int>(first_)])
                       .arg(marker_type_label(second_))
                       .arg(counts[static_cast<int>(second_)]));
}

void MarkersPage::surface_clicked(const Eigen::Vector3d& p) {
  host_.push(commands::add_marker(host_.marker_type(), p));
}

SkullView::PickTarget MarkersPage::pick_target() const {
  return marker_pick_target(host_.marker_type());
}

QString MarkersPage::keys_hint() const { return marker_keys_hint(); }

EdgeMarkersPage::EdgeMarkersPage(PageHost& host)
    : MarkersPage(kEdgeMarkersStep, host, MarkerType::OuterEdge, MarkerType::InnerEdge) {
  QPushButton* propose = add_button(tr("Propose markers automatically"), "propose");
  connect(propose, &QPushButton::clicked, this, [this] {
    // Proposed again, as the last proposal was asked (its model weighed and fitted as
    // recorded); with several openings in the skull, the one where the user has put edge
    // markers is meant (otherwise the largest).
    const PlanState& plan = host_.plan();
    const bool again = !plan.proposal_message.empty();
    ProposeParams params = again ? plan.proposal_params : ProposeParams{};
    const ShapePriorParams prior = again ? plan.proposal_prior : ShapePriorParams{};
    params.detect.center.reset();  // a start given to the last proposal: found again
    params.detect.near = edge_marker_centre(plan.markers);
    const std::string model = shape_model_path();
    if (!model.empty() && !QFileInfo::exists(QString::fromStdString(model))) {
      proposal_note_->setText(tr("The shape model %1 is missing: choose it again, or untick "
                                 "\"Guide with a model of the normal skull\".")
                                  .arg(QString::fromStdString(model)));
      proposal_note_->setVisible(true);
      return;
    }
    Command propose;
    try {
      propose = commands::propose_markers(params, model, "", prior);  // hashes the model's file
    } catch (const Error& e) {
      proposal_note_->setText(tr("The shape model could not be read: %1").arg(e.what()));
      proposal_note_->setVisible(true);
      return;
    }
    host_.push(std::move(propose),
               model.empty() ? tr("Finding the defect and proposing markers")
                             : tr("Finding the defect and proposing markers (the shape model "
                                  "fitted where the mirror does not cover it)"));
  });
  add_shape_model_row();
  QPushButton* import = add_button(tr("Import markers…"), "importMarkers");
  connect(import, &QPushButton::clicked, this, &EdgeMarkersPage::import_markers);
  QPushButton* clear = add_button(tr("Clear markers"), "clearMarkers");
  connect(clear, &QPushButton::clicked, this, [this] { host_.push(commands::clear_markers()); });
  add_counts_row();
  // What the last proposal found stays in view while the markers are edited: where the rim
  // was not seen, the outline between edge markers far apart needs a look.
  proposal_note_ = new QLabel(this);
  proposal_note_->setObjectName("proposalNote");
  proposal_note_->setWordWrap(true);
  form_->addRow(proposal_note_);
}

void EdgeMarkersPage::add_shape_model_row() {
  QSettings settings;
  use_model_ = new QCheckBox(tr("Guide with a model of the normal skull"), this);
  use_model_->setObjectName("useShapeModel");
  use_model_->setToolTip(
      tr("A statistical shape model built from normal skulls (cranioplan-cli shape-model "
         "build; docs/SHAPE_MODEL.md) is fitted to the intact bone and guides the missing "
         "vault with the mirror or the ring. A poor fit is not used, and the proposal says so."));
  use_model_->setChecked(settings.value("shapeModel/use", false).toBool());
  model_file_ = new QLabel(this);
  model_file_->setObjectName("shapeModelFile");
  model_file_->setWordWrap(true);
  show_model_file(settings.value("shapeModel/path").toString());
  QPushButton* choose = make_button(tr("Choose model…"), "chooseShapeModel");
  connect(choose, &QPushButton::clicked, this, &EdgeMarkersPage::choose_shape_model);
  connect(use_model_, &QCheckBox::toggled, this, [this](bool on) {
    QSettings().setValue("shapeModel/use", on);
    if (on && QSettings().value("shapeModel/path").toString().isEmpty()) choose_shape_model();
  });
  form_->addRow(use_model_);
  form_->addRow(model_file_, choose);
}

void EdgeMarkersPage::choose_shape_model() {
  const QString path = QFileDialog::getOpenFileName(this, tr("Model of the normal skull"),
                                                    QSettings().value("shapeModel/path").toString(),
                                                    tr("Shape models (*.cpsm)"));
  if (path.isEmpty()) {
    if (QSettings().value("shapeModel/path").toString().isEmpty()) use_model_->setChecked(false);
    return;
  }
  QSettings().setValue("shapeModel/path", path);
  plan_model_.clear();
  show_model_file(path);
  use_model_->setChecked(true);
}

void EdgeMarkersPage::show_model_file(const QString& path) {
  model_file_->setText(path.isEmpty() ? tr("No model chosen.") : QFileInfo(path).fileName());
  model_file_->setToolTip(path);
}

std::string EdgeMarkersPage::shape_model_path() const {
  if (!use_model_->isChecked()) return {};
  if (!plan_model_.isEmpty()) return plan_model_.toStdString();
  return QSettings().value("shapeModel/path").toString().toStdString();
}

void EdgeMarkersPage::show_plan_model(const PlanState& s) {
  const std::string proposal = s.proposal_message + '\n' + s.proposal_shape_model;
  if (proposal == shown_proposal_) return;
  shown_proposal_ = proposal;
  plan_model_ = QString::fromStdString(s.proposal_shape_model);
  const QSignalBlocker quiet(use_model_);  // the settings keep the user's own choice
  QSettings settings;
  if (s.proposal_message.empty()) {  // no proposal (a new plan, or undone): the settings' choice
    use_model_->setChecked(settings.value("shapeModel/use", false).toBool());
    show_model_file(settings.value("shapeModel/path").toString());
    return;
  }
  use_model_->setChecked(!plan_model_.isEmpty());
  show_model_file(plan_model_.isEmpty() ? settings.value("shapeModel/path").toString()
                                        : plan_model_);
}

void EdgeMarkersPage::import_markers() {
  const QString path = QFileDialog::getOpenFileName(this, tr("Markers"), QString(),
                                                    tr("Markers (*.mrk.json *.json *.csv)"));
  if (!path.isEmpty()) host_.import_markers(path);
}

void EdgeMarkersPage::show_state(const PlanState& s) {
  MarkersPage::show_state(s);
  show_plan_model(s);
  QString note = s.proposal_message.empty()
                     ? QString()
                     : tr("Last proposal: %1").arg(QString::fromStdString(s.proposal_message));
  if (!s.unseen_rim.empty())
    note +=
        tr(" The orange lines in the view run along the stretches of the rim no ray saw: the "
           "outline there goes straight from one edge marker to the next.");
  proposal_note_->setText(note);
  proposal_note_->setVisible(!s.proposal_message.empty());
}

SurfaceMarkersPage::SurfaceMarkersPage(PageHost& host)
    : MarkersPage(kSurfaceMarkersStep, host, MarkerType::OuterSurface, MarkerType::InnerSurface) {
  add_counts_row();
}

}  // namespace cranioplan::gui
