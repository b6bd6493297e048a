#include "slice_panel.h"

#include <QCoreApplication>
#include <QFutureWatcher>
#include <QGridLayout>
#include <QtConcurrent/QtConcurrent>

#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"

namespace cranioplan::gui {

struct SlicePanel::Read {
  std::shared_ptr<const Volume> volume;
  QString error;
};

SlicePanel::SlicePanel(QWidget* parent) : QWidget(parent), grid_(new QGridLayout(this)) {
  setObjectName("slicePanel");
  grid_->setContentsMargins(0, 0, 0, 0);
  grid_->setSpacing(2);
  for (SliceOrientation o :
       {SliceOrientation::Axial, SliceOrientation::Coronal, SliceOrientation::Sagittal}) {
    auto* v = new SliceView(o, this);
    views_[static_cast<int>(o)] = v;
    connect(v, &SliceView::cursorMoved, this, [this](const Eigen::Vector3d& p) {
      set_cursor(p);
      emit cursorMoved(p);
    });
    connect(v, &SliceView::windowLevelChanged, this, &SlicePanel::set_window_level);
  }
  set_column(true);
}

SlicePanel::~SlicePanel() {
  if (watcher_) watcher_->waitForFinished();
}

void SlicePanel::set_column(bool column) {
  for (SliceView* v : views_) grid_->removeWidget(v);
  for (int i = 0; i < 3; ++i) grid_->addWidget(views_[i], column ? i : i / 2, column ? 0 : i % 2);
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
