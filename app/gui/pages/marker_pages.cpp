#include <QFileDialog>
#include <QFormLayout>
#include <QLabel>
#include <QPushButton>

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
    : MarkersPage(5, host, MarkerType::OuterEdge, MarkerType::InnerEdge) {
  QPushButton* propose = add_button(tr("Propose markers automatically"), "propose");
  connect(propose, &QPushButton::clicked, this, [this] {
    // With several openings in the skull, the one where the user has put edge markers is
    // meant (otherwise the largest).
    ProposeParams params;
    params.detect.near = edge_marker_centre(host_.plan().markers);
    host_.push(commands::propose_markers(params), tr("Finding the defect and proposing markers"));
  });
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

void EdgeMarkersPage::import_markers() {
  const QString path = QFileDialog::getOpenFileName(this, tr("Markers"), QString(),
                                                    tr("Markers (*.mrk.json *.json *.csv)"));
  if (!path.isEmpty()) host_.import_markers(path);
}

void EdgeMarkersPage::show_state(const PlanState& s) {
  MarkersPage::show_state(s);
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
    : MarkersPage(6, host, MarkerType::OuterSurface, MarkerType::InnerSurface) {
  add_counts_row();
}

}  // namespace cranioplan::gui
