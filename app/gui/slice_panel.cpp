#include "slice_panel.h"

#include <QCoreApplication>
#include <QFutureWatcher>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QSlider>
#include <QToolButton>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrent>

#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"

namespace cranioplan::gui {

struct SlicePanel::Read {
  std::shared_ptr<const Volume> volume;
  QString error;
};

SlicePanel::SlicePanel(QWidget* three_d, QWidget* parent)
    : QWidget(parent), grid_(new QGridLayout(this)) {
  setObjectName("slicePanel");
  grid_->setContentsMargins(0, 0, 0, 0);
  grid_->setSpacing(3);
  panes_[0] = make_pane(three_d, tr("3D"), 0);
  const QString titles[] = {tr("Axial"), tr("Coronal"), tr("Sagittal")};
  for (SliceOrientation o :
       {SliceOrientation::Axial, SliceOrientation::Coronal, SliceOrientation::Sagittal}) {
    const int i = static_cast<int>(o);
    auto* v = new SliceView(o, this);
    views_[i] = v;
    connect(v, &SliceView::cursorMoved, this, [this](const Eigen::Vector3d& p) {
      set_cursor(p);
      emit cursorMoved(p);
    });
    connect(v, &SliceView::windowLevelChanged, this, &SlicePanel::set_window_level);
    connect(v, &SliceView::sliceChanged, this, [this, i] { sync_slider(i); });
    connect(v, &SliceView::maximiseToggled, this, [this, i] { maximise_[i + 1]->click(); });
    panes_[i + 1] = make_pane(v, titles[i], i + 1);
  }
  // Four equal panes: 3D top left, axial top right, coronal and sagittal below.
  for (int k = 0; k < 4; ++k) grid_->addWidget(panes_[k], k / 2, k % 2);
  for (int k = 0; k < 2; ++k) {
    grid_->setRowStretch(k, 1);
    grid_->setColumnStretch(k, 1);
  }
  arrange(Arrangement::ThreeD);
}

SlicePanel::~SlicePanel() {
  if (watcher_) watcher_->waitForFinished();
}

QWidget* SlicePanel::make_pane(QWidget* content, const QString& title, int index) {
  auto* pane = new QWidget(this);
  auto* column = new QVBoxLayout(pane);
  column->setContentsMargins(0, 0, 0, 0);
  column->setSpacing(1);
  auto* header = new QWidget(pane);
  header->setStyleSheet("background:#2b2f36;color:#e8e8e8");
  auto* row = new QHBoxLayout(header);
  row->setContentsMargins(6, 1, 2, 1);
  auto* name = new QLabel(title, header);
  name->setMinimumWidth(name->fontMetrics().horizontalAdvance(QStringLiteral("Sagittal  ")));
  row->addWidget(name);
  if (index > 0) {
    auto* slider = new QSlider(Qt::Horizontal, header);
    static const char* const kNames[] = {"sliceSliderAxial", "sliceSliderCoronal",
                                         "sliceSliderSagittal"};
    slider->setObjectName(kNames[index - 1]);
    slider->setToolTip(tr("The slice (the wheel steps it too)"));
    connect(slider, &QSlider::valueChanged, this, [this, index](int value) {
      SliceView& v = *views_[index - 1];
      const SliceView::Range r = v.range();
      v.set_slice_position(r.from + value * r.step);
    });
    sliders_[index - 1] = slider;
    row->addWidget(slider, 1);
    auto* fit = new QToolButton(header);
    fit->setText(tr("Fit"));
    fit->setToolTip(tr("The whole slice in the pane (Ctrl+wheel zooms, middle drag pans)"));
    connect(fit, &QToolButton::clicked, this, [this, index] { views_[index - 1]->fit(); });
    row->addWidget(fit);
  } else {
    row->addStretch(1);
  }
  auto* max = new QToolButton(header);
  static const char* const kMax[] = {"maximise3d", "maximiseAxial", "maximiseCoronal",
                                     "maximiseSagittal"};
  max->setObjectName(kMax[index]);
  max->setText(QStringLiteral("⤢"));
  max->setToolTip(tr("This pane alone, or back to the four (a double click on a slice too)"));
  max->setCheckable(true);
  connect(max, &QToolButton::clicked, this, [this, index](bool on) {
    static const Arrangement kOne[] = {Arrangement::ThreeDMaximised, Arrangement::Axial,
                                       Arrangement::Coronal, Arrangement::Sagittal};
    arrange(on ? kOne[index] : Arrangement::FourUp);
    emit arranged(arrangement_);
  });
  maximise_[index] = max;
  row->addWidget(max);
  headers_[index] = header;
  column->addWidget(header);
  column->addWidget(content, 1);
  return pane;
}

void SlicePanel::arrange(Arrangement a) {
  // Back to the four from one slice alone: that slice fitted again (zoomed and panned alone,
  // it would show a corner of the head among the four).
  const int alone = static_cast<int>(arrangement_) - static_cast<int>(Arrangement::Axial);
  if (a == Arrangement::FourUp && alone >= 0 && alone < 3) views_[alone]->fit();
  arrangement_ = a;
  const std::array<bool, 4> shown = {
      a == Arrangement::ThreeD || a == Arrangement::FourUp || a == Arrangement::ThreeDMaximised,
      a == Arrangement::FourUp || a == Arrangement::Axial,
      a == Arrangement::FourUp || a == Arrangement::Coronal,
      a == Arrangement::FourUp || a == Arrangement::Sagittal};
  for (int k = 0; k < 4; ++k) {
    panes_[k]->setVisible(shown[k]);
    // The 3D view alone is the plain wizard: no header.
    headers_[k]->setVisible(a != Arrangement::ThreeD);
    const QSignalBlocker block(maximise_[k]);
    maximise_[k]->setChecked(a != Arrangement::FourUp && a != Arrangement::ThreeD && shown[k]);
  }
  // A hidden pane's row or column takes no room.
  grid_->setRowStretch(0, shown[0] || shown[1] ? 1 : 0);
  grid_->setRowStretch(1, shown[2] || shown[3] ? 1 : 0);
  grid_->setColumnStretch(0, shown[0] || shown[2] ? 1 : 0);
  grid_->setColumnStretch(1, shown[1] || shown[3] ? 1 : 0);
}

void SlicePanel::sync_slider(int i) {
  QSlider* slider = sliders_[i];
  if (!slider) return;
  const SliceView::Range r = views_[i]->range();
  const QSignalBlocker block(slider);
  slider->setEnabled(views_[i]->has_volume());
  slider->setRange(0, std::max(0, r.count() - 1));
  slider->setValue(
      static_cast<int>(std::lround((views_[i]->geometry().position_mm - r.from) / r.step)));
}

void SlicePanel::show_state(const PlanState& s) {
  for (SliceView* v : views_) v->show_state(s);
  // Until the user points somewhere, the slices go through the implant (else the edge markers,
  // else the skull's middle).
  if (s.implant && s.implant->result().mesh.n_vertices() > 0) {
    plan_centre_ = vertex_centroid(s.implant->result().mesh);
  } else if (const auto edges = edge_marker_centre(s.markers)) {
    plan_centre_ = *edges;
  } else if (s.skull) {
    plan_centre_ = s.skull->centroid;
  }
  if (!cursor_set_ && volume_ && plan_centre_ != cursor_) {
    cursor_ = plan_centre_;
    for (SliceView* v : views_) v->set_cursor(cursor_);
  }
  load_ct(s);
}

void SlicePanel::load_ct(const PlanState& s) {
  const SharedSurface* skull = s.skull ? s.skull->surface.get() : nullptr;
  // The CT: the one attached to a mesh plan, or the volume the skull was imported from.
  const std::optional<AttachedCt> ct = plan_ct(s);
  std::string key, path;
  ExtractBoneSurfaceParams import;
  QString missing = tr("No CT: load a skull (step 1).");
  if (ct) {
    path = ct->path;
    import = ct->import;
    key = path + "\n" + import.dicom_series;
  } else if (skull) {
    missing = tr("No CT: this plan was made from a mesh. File → Attach CT… gives it its CT.");
  }
  if (key == key_) return;
  key_ = key;
  volume_.reset();
  for (SliceView* v : views_) v->set_volume(nullptr, key.empty() ? missing : tr("Reading the CT…"));
  for (int i = 0; i < 3; ++i) sync_slider(i);
  set_highlight({});
  emit ctChanged();
  if (key.empty()) return;
  ReadVolumeParams read;
  read.dicom_series = import.dicom_series;
  read.patient_frame = import.patient_frame;
  // An earlier read still running is of no use now: it finishes on its own and is dropped
  // (no waiting on the GUI thread).
  if (watcher_) {
    disconnect(watcher_, nullptr, this, nullptr);
    if (watcher_->isRunning())
      connect(watcher_, &QFutureWatcherBase::finished, watcher_, &QObject::deleteLater);
    else
      watcher_->deleteLater();
  }
  watcher_ = new QFutureWatcher<std::shared_ptr<Read>>(this);
  connect(watcher_, &QFutureWatcherBase::finished, this, &SlicePanel::loaded);
  watcher_->setFuture(QtConcurrent::run([path, read] {
    auto r = std::make_shared<Read>();
    try {
      r->volume = std::make_shared<const Volume>(read_volume(path, read));
    } catch (const Error& e) {
      r->error = QString::fromUtf8(e.what());
    }
    return r;
  }));
}

void SlicePanel::loaded() {
  const std::shared_ptr<Read> r = watcher_->result();
  if (!r->volume) {
    for (SliceView* v : views_)
      v->set_volume(nullptr, tr("The CT could not be read: %1").arg(r->error));
    return;
  }
  volume_ = r->volume;
  if (!cursor_set_) cursor_ = plan_centre_;
  for (SliceView* v : views_) {
    v->set_cursor(cursor_);
    v->set_volume(volume_);
  }
  for (int i = 0; i < 3; ++i) sync_slider(i);
  emit ctChanged();
}

void SlicePanel::wait_loaded() {
  while (watcher_ && watcher_->isRunning()) {
    QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
  }
  QCoreApplication::processEvents();
}

void SlicePanel::set_cursor(const Eigen::Vector3d& point) {
  cursor_ = point;
  cursor_set_ = true;
  for (SliceView* v : views_) v->set_cursor(point);
}

void SlicePanel::set_window_level(double window, double level) {
  for (SliceView* v : views_) v->set_window_level(window, level);
}

void SlicePanel::set_highlight(const std::vector<Eigen::Vector3d>& points) {
  // A voxel's centre shows on the slices within half its size of it.
  const double half = volume_ ? 0.5 * volume_->spacing().maxCoeff() : 0.5;
  for (SliceView* v : views_) v->set_highlight(points, half);
}

void SlicePanel::set_mirror_shown(bool shown) {
  for (SliceView* v : views_) v->set_mirror_shown(shown);
}

void SlicePanel::set_markers_shown(bool shown) {
  for (SliceView* v : views_) v->set_markers_shown(shown);
}

void SlicePanel::apply_preset(Preset preset) {
  if (volume_ && volume_->kind == VolumeKind::Mask) return set_window_level(1.0, 0.5);
  switch (preset) {
    case Preset::Bone:
      return set_window_level(1000.0, 400.0);
    case Preset::SoftTissue:
      return set_window_level(400.0, 40.0);
    case Preset::Brain:
      return set_window_level(80.0, 40.0);
  }
}

}  // namespace cranioplan::gui
