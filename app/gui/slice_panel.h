#pragma once
// The wizard's three CT slice views (axial, coronal, sagittal) with one shared cursor and one
// window/level. The plan's CT is the volume its skull was imported from; it is read again off
// the GUI thread when the plan's skull changes (a plan made from a mesh has none).
#include <QWidget>
#include <array>
#include <memory>
#include <string>

#include "slice_view.h"

template <typename T>
class QFutureWatcher;
class QGridLayout;

namespace cranioplan::gui {

class SlicePanel : public QWidget {
  Q_OBJECT

 public:
  explicit SlicePanel(QWidget* parent = nullptr);
  ~SlicePanel() override;

  /// Shows the plan; reads its CT when the skull changed.
  void show_state(const PlanState& state);
  void set_cursor(const Eigen::Vector3d& point);
  const Eigen::Vector3d& cursor() const { return cursor_; }
  void set_window_level(double window, double level);
  enum class Preset { Bone, SoftTissue, Brain };
  /// Window and level of a preset (a mask's 0/1 whatever the preset).
  void apply_preset(Preset preset);
  void set_markers_shown(bool shown);
  /// The three views one above the other (beside the 3D view), or in a grid.
  void set_column(bool column);
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

 private:
  void loaded();

  std::array<SliceView*, 3> views_{};
  QGridLayout* grid_;
  std::string key_;  ///< the file (and series) whose CT is shown or being read
  std::shared_ptr<const Volume> volume_;
  struct Read;
  QFutureWatcher<std::shared_ptr<Read>>* watcher_ = nullptr;
  Eigen::Vector3d cursor_ = Eigen::Vector3d::Zero();
  bool cursor_set_ = false;
  Eigen::Vector3d plan_centre_ = Eigen::Vector3d::Zero();
};

}  // namespace cranioplan::gui
