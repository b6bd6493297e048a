#pragma once
// A CT slice view of the wizard: an axial, coronal or sagittal slice of the plan's CT in the
// patient frame, with window/level, the skull's, the mirrored skull's and the implant's cut
// outlines, the markers near
// the slice, a crosshair at the shared cursor and the orientation letters at its edges. Wheel:
// the next or previous slice; Ctrl+wheel: zoom about the pointer; middle drag (or Shift+left
// drag): pan; left click or drag: moves the cursor (all views follow); right drag: window
// (left–right) and level (up–down); double click: the view maximised or back. The slicing and
// cutting are algorithms (cranioplan/algorithms/geometry/slices.h); the view only draws them.
#include <QImage>
#include <QWidget>
#include <cmath>
#include <memory>
#include <optional>

#include "cranioplan/algorithms/geometry/slices.h"
#include "cranioplan/sessions/plan_state.h"

namespace cranioplan::gui {

class SliceView : public QWidget {
  Q_OBJECT

 public:
  explicit SliceView(SliceOrientation orientation, QWidget* parent = nullptr);

  SliceOrientation orientation() const { return orientation_; }
  /// The CT to show (null: none, and the view says why with `missing`).
  void set_volume(std::shared_ptr<const Volume> volume, const QString& missing = QString());
  /// Shows the plan's skull, implant and markers over the slice.
  void show_state(const PlanState& state);
  /// Moves the slice through `point` and the crosshair onto it.
  void set_cursor(const Eigen::Vector3d& point);
  void set_window_level(double window, double level);
  /// Points drawn red where they lie in the slice (the implant's voxels in soft tissue).
  void set_highlight(std::vector<Eigen::Vector3d> points, double half_thickness_mm);
  int highlighted() const;  ///< how many of them the current slice shows
  /// Whether the markers near the slice are drawn over it.
  void set_markers_shown(bool shown);
  /// Whether the mirrored skull's outline is drawn (View → Show mirrored skull, M).
  void set_mirror_shown(bool shown);
  double window() const { return window_; }
  double level() const { return level_; }
  const SliceGeometry& geometry() const { return slice_; }
  bool has_volume() const { return volume_ != nullptr; }
  /// Where a patient point shows in the widget (logical pixels).
  QPointF to_widget(const Eigen::Vector3d& point) const;
  /// The patient point on the slice under a widget position.
  Eigen::Vector3d to_patient(const QPointF& position) const;
  /// Where slices of this orientation can lie (mm along the normal: the volume's extent) and the
  /// step between them (the wheel's); {0, 0, 1} without a volume.
  struct Range {
    double from = 0.0, to = 0.0, step = 1.0;
    int count() const { return 1 + static_cast<int>(std::lround((to - from) / step)); }
  };
  Range range() const;
  /// Moves the slice to `position_mm` along the normal (the cursor moves with it).
  void set_slice_position(double position_mm);
  /// Magnification over the whole slice fitted to the view (1: fitted), about the widget point
  /// `about` (kept where it is).
  void zoom_by(double factor, const QPointF& about);
  void pan_by(const QPointF& pixels);
  /// The whole slice fitted to the view again.
  void fit();
  double zoom() const { return zoom_; }
  /// How many outline segments of the skull and of the implant the slice shows.
  int skull_segments() const { return static_cast<int>(skull_cut_.size()); }
  int implant_segments() const { return static_cast<int>(implant_cut_.size()); }
  int mirror_segments() const { return static_cast<int>(mirror_cut_.size()); }

 signals:
  void cursorMoved(const Eigen::Vector3d& point);
  void windowLevelChanged(double window, double level);
  /// The slice moved (its position along the normal, mm).
  void sliceChanged(double position_mm);
  /// A double click: the view maximised, or back among the others.
  void maximiseToggled();

 protected:
  void paintEvent(QPaintEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;
  void mouseDoubleClickEvent(QMouseEvent* event) override;

 private:
  void reslice();  ///< the image and the outlines for the current slice
  void recut();    ///< the outlines alone (the plan changed)
  void draw_outline(class QPainter& p, const std::vector<CutSegment>& cut, const QColor& color,
                    double width) const;
  /// Pixels of the widget per pixel of the slice, and where the slice's pixel (0,0) is drawn.
  double scale() const;
  QPointF offset() const;

  SliceOrientation orientation_;
  std::shared_ptr<const Volume> volume_;
  QString missing_;
  SliceGeometry slice_;
  std::vector<float> values_;
  QImage image_;
  double window_ = 1000.0, level_ = 400.0;
  Eigen::Vector3d cursor_ = Eigen::Vector3d::Zero();
  std::shared_ptr<const SharedSurface> skull_;
  std::shared_ptr<const MovedSurface> mirror_;  ///< the mirrored skull where the plan put it
  std::shared_ptr<const ImplantData> implant_;
  std::vector<Marker> markers_;
  bool markers_shown_ = false;
  bool mirror_shown_ = true;
  std::vector<Eigen::Vector3d> highlight_;
  double highlight_half_mm_ = 0.5;
  std::vector<CutSegment> skull_cut_, mirror_cut_, implant_cut_;
  double zoom_ = 1.0;
  QPointF pan_;  ///< widget pixels
  enum class Drag { None, Cursor, WindowLevel, Pan } drag_ = Drag::None;
  QPointF drag_start_;
  double window_start_ = 0.0, level_start_ = 0.0;
};

}  // namespace cranioplan::gui
