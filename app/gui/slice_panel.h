#pragma once
// The wizard's centre: the 3D view and the three CT slice views (axial, coronal, sagittal) in
// equal panes (four-up, as 3D Slicer and InVesalius lay them out), or one of them maximised;
// each slice with a slider, one shared cursor and one window/level. The plan's CT is the volume
// its skull was imported from; it is read again off the GUI thread when the plan's skull
// changes (a plan made from a mesh has none).
#include <QWidget>
#include <array>
#include <memory>
#include <string>

#include "slice_view.h"

template <typename T>
class QFutureWatcher;
class QGridLayout;
class QLabel;
class QSlider;
class QToolButton;

namespace cranioplan::gui {

class SlicePanel : public QWidget {
  Q_OBJECT

 public:
  /// `three_d`: the 3D view, laid out as the first pane.
  explicit SlicePanel(QWidget* three_d, QWidget* parent = nullptr);
  ~SlicePanel() override;

  /// What the centre shows: the 3D view alone, the four panes, or one pane maximised.
  enum class Arrangement { ThreeD, FourUp, Axial, Coronal, Sagittal, ThreeDMaximised };
  void arrange(Arrangement arrangement);
  Arrangement arrangement() const { return arrangement_; }
  /// The slider of a slice view.
  QSlider& slider(SliceOrientation orientation) { return *sliders_[static_cast<int>(orientation)]; }

  /// Shows the plan; reads its CT when the skull changed.
  void show_state(const PlanState& state);
  /// Reads the plan's CT (in the background) when it is another than the one read, whether or
  /// not the slices are shown: the quality check's soft tissue needs it.
  void load_ct(const PlanState& state);
  void set_cursor(const Eigen::Vector3d& point);
  const Eigen::Vector3d& cursor() const { return cursor_; }
  void set_window_level(double window, double level);
  enum class Preset { Bone, SoftTissue, Brain };
  /// Window and level of a preset (a mask's 0/1 whatever the preset).
  void apply_preset(Preset preset);
  void set_markers_shown(bool shown);
  void set_mirror_shown(bool shown);
  SliceView& view(SliceOrientation orientation) { return *views_[static_cast<int>(orientation)]; }
  /// Waits (processing events) until the CT is read; for tests and the command line.
  void wait_loaded();
  bool has_ct() const { return volume_ != nullptr; }
  /// The CT shown (null: none).
  std::shared_ptr<const Volume> ct() const { return volume_; }
  /// Marks points red on the slices they lie in (the implant's voxels in soft tissue).
  void set_highlight(const std::vector<Eigen::Vector3d>& points);

 signals:
  void cursorMoved(const Eigen::Vector3d& point);
  /// The plan's CT has been read (or is gone).
  void ctChanged();
  /// The arrangement changed from within (a pane's maximise button, a double click).
  void arranged(Arrangement arrangement);

 private:
  void loaded();
  /// A pane: a header (its name, the slice slider, maximise) over `content`.
  QWidget* make_pane(QWidget* content, const QString& title, int index);
  /// The sliders' ranges and positions as the views' slices are.
  void sync_slider(int orientation);

  std::array<SliceView*, 3> views_{};
  std::array<QSlider*, 3> sliders_{};
  std::array<QWidget*, 4> panes_{};  ///< 3D, axial, coronal, sagittal
  std::array<QToolButton*, 4> maximise_{};
  std::array<QWidget*, 4> headers_{};
  QGridLayout* grid_;
  Arrangement arrangement_ = Arrangement::ThreeD;
  std::string key_;  ///< the file (and series) whose CT is shown or being read
  std::shared_ptr<const Volume> volume_;
  struct Read;
  QFutureWatcher<std::shared_ptr<Read>>* watcher_ = nullptr;
  Eigen::Vector3d cursor_ = Eigen::Vector3d::Zero();
  bool cursor_set_ = false;
  Eigen::Vector3d plan_centre_ = Eigen::Vector3d::Zero();
};

}  // namespace cranioplan::gui
