#pragma once
// A CT slice view of the wizard: an axial, coronal or sagittal slice of the plan's CT in the
// patient frame, with window/level, the skull's and the implant's cut outlines, the markers near
// the slice, a crosshair at the shared cursor and the orientation letters at its edges. Wheel:
// the next or previous slice; left click or drag: moves the cursor (all views follow); right
// drag: window (left–right) and level (up–down). The slicing and cutting are algorithms
// (cranioplan/algorithms/geometry/slices.h); the view only draws them.
#include <QImage>
#include <QWidget>
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
  double window() const { return window_; }
  double level() const { return level_; }
  const SliceGeometry& geometry() const { return slice_; }
  bool has_volume() const { return volume_ != nullptr; }
  /// Where a patient point shows in the widget (logical pixels).
  QPointF to_widget(const Eigen::Vector3d& point) const;
  /// The patient point on the slice under a widget position.
  Eigen::Vector3d to_patient(const QPointF& position) const;
  /// How many outline segments of the skull and of the implant the slice shows.
  int skull_segments() const { return static_cast<int>(skull_cut_.size()); }
  int implant_segments() const { return static_cast<int>(implant_cut_.size()); }

 signals:
  void cursorMoved(const Eigen::Vector3d& point);
  void windowLevelChanged(double window, double level);

 protected:
  void paintEvent(QPaintEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;

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
  std::shared_ptr<const ImplantData> implant_;
  std::vector<Marker> markers_;
  bool markers_shown_ = true;
  std::vector<Eigen::Vector3d> highlight_;
  double highlight_half_mm_ = 0.5;
  std::vector<CutSegment> skull_cut_, implant_cut_;
  enum class Drag { None, Cursor, WindowLevel } drag_ = Drag::None;
  QPointF drag_start_;
  double window_start_ = 0.0, level_start_ = 0.0;
};

}  // namespace cranioplan::gui
