#include "slice_view.h"

#include <QFontMetrics>
#include <QMouseEvent>
#include <QPainter>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>
#include <limits>

namespace cranioplan::gui {

namespace {

// Markers this close to the slice (mm) are drawn on it.
constexpr double kMarkerNearMm = 2.0;

QColor marker_color(MarkerType t) {
  return is_edge(t) ? QColor(40, 200, 70) : QColor(220, 60, 220);
}

}  // namespace

SliceView::SliceView(SliceOrientation orientation, QWidget* parent)
    : QWidget(parent), orientation_(orientation) {
  setObjectName(QStringLiteral("slice_%1").arg(to_string(orientation)));
  setMinimumSize(160, 160);
  setMouseTracking(false);
  setAttribute(Qt::WA_OpaquePaintEvent);
}

void SliceView::set_volume(std::shared_ptr<const Volume> volume, const QString& missing) {
  volume_ = std::move(volume);
  missing_ = missing;
  if (volume_ && volume_->kind == VolumeKind::Mask) window_ = 1.0, level_ = 0.5;
  reslice();
}

void SliceView::show_state(const PlanState& s) {
  const std::shared_ptr<const SharedSurface> skull = s.skull ? s.skull->surface : nullptr;
  const bool changed = skull != skull_ || s.implant != implant_ || s.mirrored != mirror_;
  skull_ = skull;
  mirror_ = s.mirrored;
  implant_ = s.implant;
  markers_ = s.markers;
  if (changed) recut();
  update();
}

void SliceView::set_cursor(const Eigen::Vector3d& point) {
  const double before = slice_.position_mm;
  cursor_ = point;
  if (!volume_) return;
  const SliceGeometry next = slice_through(*volume_, orientation_, point);
  if (next.position_mm != before || next.width != slice_.width || image_.isNull())
    reslice();
  else
    update();
}

void SliceView::set_window_level(double window, double level) {
  window_ = std::max(window, 1e-3);
  level_ = level;
  if (!volume_) return;
  const std::vector<uint8_t> grey = window_level(values_, window_, level_);
  image_ = QImage(slice_.width, slice_.height, QImage::Format_Grayscale8);
  for (int r = 0; r < slice_.height; ++r)
    std::copy_n(grey.data() + static_cast<size_t>(r) * slice_.width, slice_.width,
                image_.scanLine(r));
  update();
}

void SliceView::set_highlight(std::vector<Eigen::Vector3d> points, double half_thickness_mm) {
  highlight_ = std::move(points);
  highlight_half_mm_ = half_thickness_mm;
  update();
}

int SliceView::highlighted() const {
  int n = 0;
  for (const Eigen::Vector3d& p : highlight_)
    n += std::abs(slice_.distance(p)) <= highlight_half_mm_;
  return n;
}

void SliceView::set_mirror_shown(bool shown) {
  mirror_shown_ = shown;
  update();
}

void SliceView::set_markers_shown(bool shown) {
  markers_shown_ = shown;
  update();
}

void SliceView::reslice() {
  if (!volume_) {
    image_ = QImage();
    update();
    return;
  }
  const double before = slice_.position_mm;
  slice_ = slice_through(*volume_, orientation_, cursor_);
  values_ = sample_slice(*volume_, slice_);
  recut();
  set_window_level(window_, level_);
  if (slice_.position_mm != before) emit sliceChanged(slice_.position_mm);
}

SliceView::Range SliceView::range() const {
  Range r;
  if (!volume_) return r;
  r.from = std::numeric_limits<double>::infinity();
  r.to = -r.from;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d ijk((corner & 1) ? volume_->dims[0] - 1 : 0,
                              (corner & 2) ? volume_->dims[1] - 1 : 0,
                              (corner & 4) ? volume_->dims[2] - 1 : 0);
    const double along = slice_.normal.dot(volume_->world(ijk));
    r.from = std::min(r.from, along);
    r.to = std::max(r.to, along);
  }
  r.step = std::max(1e-3, slice_.right.norm());
  return r;
}

void SliceView::set_slice_position(double position_mm) {
  if (!volume_) return;
  emit cursorMoved(cursor_ + (position_mm - slice_.normal.dot(cursor_)) * slice_.normal);
}

void SliceView::zoom_by(double factor, const QPointF& about) {
  const double next = std::clamp(zoom_ * factor, 1.0, 20.0);
  // The point under `about` stays there: the offset scales about it.
  const QPointF o = offset();
  const double k = next / zoom_;
  zoom_ = next;
  const QPointF centred =
      QPointF((width() - scale() * slice_.width) / 2.0, (height() - scale() * slice_.height) / 2.0);
  pan_ = about - (about - o) * k - centred;
  if (zoom_ == 1.0) pan_ = QPointF();
  update();
}

void SliceView::pan_by(const QPointF& pixels) {
  pan_ += pixels;
  update();
}

void SliceView::fit() {
  zoom_ = 1.0;
  pan_ = QPointF();
  update();
}

void SliceView::recut() {
  skull_cut_.clear();
  mirror_cut_.clear();
  implant_cut_.clear();
  if (!volume_) return;
  if (skull_) skull_cut_ = cut_mesh(skull_->mesh, slice_.normal, slice_.position_mm);
  if (mirror_) {
    // The mirror is the skull moved by its placement x = A y + t: the slice n·x = d is, in the
    // skull's own frame, (Aᵀn)·y = d − n·t; its cut is moved back into place.
    const RigidTransform& m = mirror_->placement;
    const Eigen::Vector3d n = m.rotation.transpose() * slice_.normal;
    const double d = slice_.position_mm - slice_.normal.dot(m.translation);
    mirror_cut_ = cut_mesh(mirror_->skull->mesh, n.normalized(), d / n.norm());
    for (CutSegment& c : mirror_cut_)
      for (Eigen::Vector3d& p : c) p = m.apply(p);
  }
  if (implant_) implant_cut_ = cut_mesh(implant_->result().mesh, slice_.normal, slice_.position_mm);
}

double SliceView::scale() const {
  if (slice_.width == 0 || slice_.height == 0) return 1.0;
  return zoom_ * std::min(width() / static_cast<double>(slice_.width),
                          height() / static_cast<double>(slice_.height));
}

QPointF SliceView::offset() const {
  const double s = scale();
  return QPointF((width() - s * slice_.width) / 2.0, (height() - s * slice_.height) / 2.0) + pan_;
}

QPointF SliceView::to_widget(const Eigen::Vector3d& point) const {
  // Pixel (c, r)'s sample is drawn at the centre of its square.
  const Eigen::Vector2d px = slice_.pixel(point);
  const double s = scale();
  return offset() + QPointF((px.x() + 0.5) * s, (px.y() + 0.5) * s);
}

Eigen::Vector3d SliceView::to_patient(const QPointF& position) const {
  const double s = scale();
  const QPointF q = (position - offset()) / s - QPointF(0.5, 0.5);
  return slice_.world(q.x(), q.y());
}

void SliceView::draw_outline(QPainter& p, const std::vector<CutSegment>& cut, const QColor& color,
                             double width) const {
  p.setPen(QPen(color, width));
  for (const CutSegment& s : cut) p.drawLine(to_widget(s[0]), to_widget(s[1]));
}

void SliceView::paintEvent(QPaintEvent*) {
  QPainter p(this);
  p.fillRect(rect(), Qt::black);
  p.setPen(QColor(200, 200, 200));
  if (!volume_ || image_.isNull()) {
    p.drawText(rect().adjusted(12, 12, -12, -12), Qt::AlignCenter | Qt::TextWordWrap,
               missing_.isEmpty() ? tr("No CT") : missing_);
    return;
  }
  const double s = scale();
  const QPointF o = offset();
  p.setRenderHint(QPainter::SmoothPixmapTransform, true);
  p.drawImage(QRectF(o, QSizeF(s * slice_.width, s * slice_.height)), image_);
  p.setRenderHint(QPainter::Antialiasing, true);
  // The crosshair at the cursor, under the outlines it would hide.
  const QPointF c = to_widget(cursor_);
  p.setPen(QPen(QColor(0, 220, 255, 170), 1, Qt::DashLine));
  p.drawLine(QPointF(o.x(), c.y()), QPointF(o.x() + s * slice_.width, c.y()));
  p.drawLine(QPointF(c.x(), o.y()), QPointF(c.x(), o.y() + s * slice_.height));
  draw_outline(p, skull_cut_, QColor(240, 220, 90), 1.0);
  if (mirror_shown_) draw_outline(p, mirror_cut_, QColor(90, 210, 110, 200), 1.0);  // as in 3D
  // Where the implant lies in soft tissue: its voxels in this slice, red.
  p.setPen(Qt::NoPen);
  p.setBrush(QColor(255, 30, 30, 190));
  const double dot = std::max(2.0, s * 0.9);
  for (const Eigen::Vector3d& h : highlight_)
    if (std::abs(slice_.distance(h)) <= highlight_half_mm_)
      p.drawRect(QRectF(to_widget(h) - QPointF(dot / 2, dot / 2), QSizeF(dot, dot)));
  for (const Marker& m : markers_) {
    if (!markers_shown_) break;
    const double d = slice_.distance(m.position);
    if (std::abs(d) > kMarkerNearMm) continue;
    p.setPen(QPen(Qt::black, 1));
    p.setBrush(marker_color(m.type));
    p.drawEllipse(to_widget(m.position), 3.5, 3.5);
  }
  // The implant's outline over everything else: what the slice is looked at for.
  p.setBrush(Qt::NoBrush);
  draw_outline(p, implant_cut_, QColor(255, 130, 0), 2.0);
  // Orientation letters at the middle of the image's edges (within the widget, whatever the
  // zoom); the slice's position and the window and level in the widget's corners, each on a
  // dark card so that they read over bone.
  const QRectF image(o, QSizeF(s * slice_.width, s * slice_.height));
  QFont f = font();
  f.setBold(true);
  p.setFont(f);
  p.setPen(QColor(255, 230, 120));
  const QRectF letters = image.intersected(QRectF(rect())).adjusted(3, 1, -3, -1);
  p.drawText(letters, Qt::AlignLeft | Qt::AlignVCenter, slice_.edge_labels[0]);
  p.drawText(letters, Qt::AlignRight | Qt::AlignVCenter, slice_.edge_labels[1]);
  p.drawText(letters, Qt::AlignHCenter | Qt::AlignTop, slice_.edge_labels[2]);
  p.drawText(letters, Qt::AlignHCenter | Qt::AlignBottom, slice_.edge_labels[3]);
  f.setBold(false);
  f.setPointSizeF(f.pointSizeF() * 0.85);
  p.setFont(f);
  const auto card = [&p](const QRectF& within, int align, const QString& text) {
    const QRectF box = p.boundingRect(within, align, text).adjusted(-3, -1, 3, 1);
    p.fillRect(box, QColor(0, 0, 0, 170));
    p.setPen(QColor(225, 225, 225));
    p.drawText(within, align, text);
  };
  static const char* const kAxis[] = {"z", "y", "x"};
  const QRectF corners = QRectF(rect()).adjusted(5, 3, -5, -3);
  card(corners, Qt::AlignLeft | Qt::AlignTop,
       tr("%1\n%2 = %3 mm")
           .arg(QString::fromLatin1(to_string(orientation_)))
           .arg(QString::fromLatin1(kAxis[static_cast<int>(orientation_)]))
           .arg(slice_.position_mm, 0, 'f', 1));
  card(corners, Qt::AlignRight | Qt::AlignBottom,
       tr("W %1\nL %2").arg(window_, 0, 'g', 4).arg(level_, 0, 'g', 4));
  // What the lines and colours are, in the upper right.
  {
    const std::pair<QColor, QString> keys[] = {{QColor(255, 130, 0), tr("implant")},
                                               {QColor(240, 220, 90), tr("bone")},
                                               {QColor(90, 210, 110), tr("mirror")},
                                               {QColor(255, 30, 30), tr("brain/dura in it")}};
    const QFontMetrics fm(p.font());
    int wide = 0;
    for (const auto& k : keys) wide = std::max(wide, fm.horizontalAdvance(k.second));
    const double line = fm.height();
    const QRectF box(corners.right() - wide - 26, corners.top(), wide + 26, 4 * line + 4);
    p.fillRect(box, QColor(0, 0, 0, 170));
    for (int k = 0; k < 4; ++k) {
      const double y = box.top() + 2 + (k + 0.5) * line;
      p.setPen(QPen(keys[k].first, 2));
      p.drawLine(QPointF(box.left() + 4, y), QPointF(box.left() + 18, y));
      p.setPen(QColor(225, 225, 225));
      p.drawText(QRectF(box.left() + 22, y - line / 2, wide + 4, line), Qt::AlignVCenter,
                 keys[k].second);
    }
  }
  // A scale bar (10 mm) in the lower left: the slice's millimetres at a glance, at any zoom.
  const double ten = 10.0 * s / std::max(1e-9, slice_.right.norm());
  const QString scale_text = zoom_ > 1.0 ? tr("10 mm  ×%1").arg(zoom_, 0, 'f', 1) : tr("10 mm");
  const QPointF bar(corners.left() + 4, corners.bottom() - 6);
  const QRectF label(bar.x(), bar.y() - 20, std::max(40.0, ten + 30), 16);
  p.fillRect(QRectF(bar.x() - 4, label.top() - 1,
                    std::max(ten, p.fontMetrics().horizontalAdvance(scale_text) * 1.0) + 8,
                    bar.y() - label.top() + 6),
             QColor(0, 0, 0, 170));
  p.setPen(QPen(QColor(220, 220, 220), 2));
  p.drawLine(bar, bar + QPointF(ten, 0));
  p.drawText(label, Qt::AlignLeft, scale_text);
}

void SliceView::mousePressEvent(QMouseEvent* e) {
  if (!volume_) return;
  drag_start_ = e->position();
  if (e->button() == Qt::MiddleButton ||
      (e->button() == Qt::LeftButton && (e->modifiers() & Qt::ShiftModifier))) {
    drag_ = Drag::Pan;
  } else if (e->button() == Qt::LeftButton) {
    drag_ = Drag::Cursor;
    emit cursorMoved(to_patient(e->position()));
  } else if (e->button() == Qt::RightButton) {
    drag_ = Drag::WindowLevel;
    window_start_ = window_;
    level_start_ = level_;
  }
}

void SliceView::mouseMoveEvent(QMouseEvent* e) {
  if (drag_ == Drag::Pan) {
    pan_by(e->position() - drag_start_);
    drag_start_ = e->position();
  } else if (drag_ == Drag::Cursor) {
    emit cursorMoved(to_patient(e->position()));
  } else if (drag_ == Drag::WindowLevel) {
    // One widget width of drag doubles (or halves) the window; one height moves the level by
    // the window.
    const QPointF d = e->position() - drag_start_;
    const double w = window_start_ * std::pow(2.0, d.x() / std::max(1, width()));
    const double l = level_start_ - window_start_ * d.y() / std::max(1, height());
    set_window_level(w, l);
    emit windowLevelChanged(window_, level_);
  }
}

void SliceView::mouseReleaseEvent(QMouseEvent*) { drag_ = Drag::None; }

void SliceView::mouseDoubleClickEvent(QMouseEvent* e) {
  if (e->button() == Qt::LeftButton) emit maximiseToggled();
}

void SliceView::wheelEvent(QWheelEvent* e) {
  if (!volume_ || e->angleDelta().y() == 0) return;
  if (e->modifiers() & Qt::ControlModifier) {  // zoom about the pointer, 1.25× a notch
    zoom_by(std::pow(1.25, e->angleDelta().y() / 120.0), e->position());
    return;
  }
  // One step: the slice's pixel size (the CT's finest spacing) along its normal.
  const double step = slice_.right.norm() * (e->angleDelta().y() > 0 ? 1.0 : -1.0);
  emit cursorMoved(cursor_ + step * slice_.normal);
}

}  // namespace cranioplan::gui
