#pragma once
// The wizard's 3D view: VTK rendering inside a Qt6 QOpenGLWidget (a vtkGenericOpenGLRenderWindow
// drawing with Qt's context). Shows a plan's state — skull, mirrored skull, landmarks, markers,
// midsagittal plane, implant, clip plane — and turns clicks and drags into surface points. It
// computes no geometry of the plan: the window turns its signals into session commands.
#include <QOpenGLWidget>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/quality/thickness_map.h"
#include "cranioplan/model/marker.h"
#include "cranioplan/sessions/plan_state.h"

namespace cranioplan {
struct MouldResult;
}

namespace cranioplan::gui {

/// The patient's direction `direction` points to (LPS frame) as radiology viewers letter it:
/// "L", "R", "A", "P", "S" or "I", two letters when it is oblique by more than 22.5°.
std::string patient_direction_letters(const Eigen::Vector3d& direction);

class SkullView : public QOpenGLWidget {
  Q_OBJECT

 public:
  /// The OpenGL surface VTK needs (core profile 3.2+, depth, stencil and alpha for depth
  /// peeling). Call before the QApplication is made.
  static void set_default_surface_format();

  explicit SkullView(QWidget* parent = nullptr);
  ~SkullView() override;

  /// Shows the state (meshes are converted once per mesh and reused).
  void show_state(const PlanState& state);
  void set_mirror_visible(bool visible);
  void set_mirror_opacity(double opacity);
  void set_plane_visible(bool visible);

  enum class StandardView { Front, Back, Left, Right, Top };
  /// The camera along a patient axis, framing the skull (not the plane or the markers).
  void set_standard_view(StandardView view);
  /// Where the camera is (position, focal point, up, view angle), to be put back.
  std::array<double, 10> camera() const;
  void set_camera(const std::array<double, 10>& camera);
  /// The letters at the view's left, right, top and bottom edges for the camera now.
  std::array<std::string, 4> edge_letters();
  /// Whether the plan's clip plane (step 4) cuts the skulls in the view; off: the whole skulls
  /// (the plane stays in the plan).
  void set_clip_enabled(bool enabled);
  bool clip_shown() const;
  void reset_camera();
  /// Looks at the markers (the defect) from outside the skull.
  void look_at_markers();
  /// The implant and the bone around it filling the view, from a standard direction or (none)
  /// along the defect, from outside the skull.
  void look_at_implant(std::optional<StandardView> from = std::nullopt);
  /// Whether markers, landmarks, handles, zones and the rim's unseen stretches are drawn (the
  /// design report's pictures: off).
  void set_markers_visible(bool visible);

  /// Which surface a click places on (None: clicks only select markers).
  enum class PickTarget { None, Original, Mirrored, Implant };
  void set_pick_target(PickTarget target);
  /// Whether markers can be dragged (steps 5, 6 and 8).
  void set_markers_editable(bool editable);
  /// A part of the implant the user can drag (a tab, a hole): drawn as a small blue ball; a
  /// press on it and a move slide it over `surface`, and the drop is reported once
  /// (`handleDropped`). A press and release without a move is a click like any other.
  struct Handle {
    int id = 0;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    PickTarget surface = PickTarget::Original;
  };
  void set_handles(std::vector<Handle> handles);
  int handles_shown() const;
  void set_selected_marker(int id);
  /// The slice views' cursor, drawn as a small cyan ball (none: hidden).
  void set_cursor(const std::optional<Eigen::Vector3d>& point);
  /// The thickness map of `implant` (computed off the GUI thread): shown, when it is on and
  /// `implant` is the implant shown, as the implant coloured by its thickness and the skull
  /// near it by its gap to the implant, each with a legend.
  void set_thickness_map(const SkullMesh* implant, std::shared_ptr<const ThicknessMap> map);
  void set_thickness_visible(bool visible);
  /// A casting mould made ready for drawing: its halves turned into VTK's meshes, which takes
  /// a few tenths of a second for a real mould, so it is done on the worker that made it.
  struct PreparedMould;
  static std::shared_ptr<const PreparedMould> prepare_mould(
      std::shared_ptr<const MouldResult> mould);
  static const MouldResult& result_of(const PreparedMould& prepared);
  /// A casting mould of the implant shown (none: hidden): its two halves drawn translucent,
  /// opened apart along their pull so the implant shows between them.
  void set_mould(std::shared_ptr<const PreparedMould> mould);
  bool mould_shown() const;
  /// Whether the thickness map is drawn now.
  bool thickness_shown() const;
  int selected_marker() const;
  /// How many named landmarks carry their name in the view.
  int landmark_names_shown() const;
  /// How many stretches of the rim no ray saw are drawn (the last proposal's).
  int unseen_rim_shown() const;
  /// A ball where the implant's edge stands furthest off the bone (the quality report's worst
  /// rim arc), drawn over the scene; none with nullopt.
  void set_rim_gap(const std::optional<Eigen::Vector3d>& at);
  bool rim_gap_shown() const;

  /// While the camera moves, meshes of more than 150,000 triangles are drawn from coarse copies
  /// (quadric clustering, 3 mm): a drag of the camera, a wheel turn or a drag of a marker or
  /// handle sets it, and it ends 250 ms after the camera stops or the drop.
  void set_moving(bool moving);
  /// Draws `frames` frames turning the camera once around, moving (the coarse copies) or at
  /// rest, and gives each one's time in ms; moving, the first entry is the time taken to make
  /// the coarse copies (none when they were made already). `cranioplan --turn N`.
  std::vector<double> time_turn(int frames, bool moving);
  /// How many meshes are drawn from their coarse copies now.
  int coarse_layers_drawn() const;
  /// Waits for the skull's coarse copy, made on a worker when a large skull is shown (else
  /// the first move makes it).
  void wait_for_coarse_copies();

  /// Where a world point shows in the widget (logical pixels), if in front of the camera.
  std::optional<QPoint> project(const Eigen::Vector3d& world);
  /// The surface point under a widget position, on the given surface.
  std::optional<Eigen::Vector3d> pick(const QPoint& position, PickTarget target);

 signals:
  void surfaceClicked(const Eigen::Vector3d& point);
  /// A click (not a drag) on the skull, in any step: the slice views go there.
  void pointed(const Eigen::Vector3d& point);
  void markerClicked(int id);
  /// A marker being dragged is over `point` (on its surface): for a preview.
  void markerDragging(int id, const Eigen::Vector3d& point);
  /// A marker dragged and let go at `point`: one move.
  void markerDragged(int id, const Eigen::Vector3d& point);
  void handleDropped(int id, const Eigen::Vector3d& point);
  /// The first frame that shows a skull has been drawn (once per view).
  void skullFirstDrawn();

 protected:
  void initializeGL() override;
  void paintGL() override;
  void resizeGL(int w, int h) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;

 private:
  /// A press or release of a mouse button, handed to VTK's interactor (camera control).
  void forward_button(QMouseEvent* event, bool press);
  /// Takes the worker's coarse copy of the skull, if it is done and of the skull shown.
  void take_coarse_copy();
  void update_edge_letters();

  struct Impl;
  std::unique_ptr<Impl> d_;
};

}  // namespace cranioplan::gui
