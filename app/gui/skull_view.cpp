// glew must come before any Qt OpenGL header.
#include <vtk_glew.h>
// clang-format off
#include "skull_view.h"
// clang-format on

#include <vtkActor.h>
#include <vtkActorCollection.h>
#include <vtkAnnotatedCubeActor.h>
#include <vtkBillboardTextActor3D.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCoordinate.h>
#include <vtkCubeSource.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGenericRenderWindowInteractor.h>
#include <vtkGlyph3DMapper.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLookupTable.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkPlane.h>
#include <vtkPlaneCollection.h>
#include <vtkPlaneSource.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkQuadricClustering.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>

#include <Eigen/Geometry>
#include <QElapsedTimer>
#include <QFutureWatcher>
#include <QMouseEvent>
#include <QSurfaceFormat>
#include <QTimer>
#include <QWheelEvent>
#include <QtConcurrent/QtConcurrent>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "cranioplan/algorithms/implant/casting_mould.h"

namespace cranioplan::gui {

namespace {

// The mesh's points and triangles.
vtkSmartPointer<vtkPolyData> bare_polydata(const SkullMesh& mesh) {
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.n_vertices()));
  for (auto vh : mesh.vertices()) {
    const auto& p = mesh.point(vh);
    points->SetPoint(vh.idx(), p[0], p[1], p[2]);
  }
  vtkNew<vtkCellArray> triangles;
  triangles->AllocateExact(static_cast<vtkIdType>(mesh.n_faces()),
                           3 * static_cast<vtkIdType>(mesh.n_faces()));
  for (auto fh : mesh.faces()) {
    vtkIdType ids[3];
    int k = 0;
    for (auto vh : mesh.fv_range(fh)) {
      if (k < 3) ids[k] = vh.idx();
      ++k;
    }
    if (k == 3) triangles->InsertNextCell(3, ids);
  }
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(triangles);
  return poly;
}

// The same with point normals, for drawing.
vtkSmartPointer<vtkPolyData> to_polydata(const SkullMesh& mesh) {
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(bare_polydata(mesh));
  normals->SplittingOff();
  normals->ConsistencyOff();
  normals->AutoOrientNormalsOff();
  normals->ComputePointNormalsOn();
  normals->Update();
  vtkSmartPointer<vtkPolyData> out = normals->GetOutput();
  return out;
}

// The same points and normals with every triangle wound the other way, for drawing with a
// reflection: the reflection turns the winding back, so OpenGL's front faces and VTK's two-sided
// lighting agree again (with the skull's own winding the reflected mirror was lit from behind).
// Only the triangles are new: the mirror has no mesh or polydata of its own, which would cost
// several times as much (docs/decisions/0030-memory-huge-pages-one-arena-no-copies.md).
vtkSmartPointer<vtkPolyData> reversed_winding(vtkPolyData* source) {
  vtkCellArray* polys = source->GetPolys();
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(polys->GetNumberOfCells(), polys->GetNumberOfConnectivityIds());
  vtkIdType n = 0;
  const vtkIdType* ids = nullptr;
  std::vector<vtkIdType> reversed;
  for (polys->InitTraversal(); polys->GetNextCell(n, ids);) {
    reversed.assign(ids, ids + n);
    std::reverse(reversed.begin() + (n > 0 ? 1 : 0), reversed.end());
    cells->InsertNextCell(n, reversed.data());
  }
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->SetPoints(source->GetPoints());
  out->SetPolys(cells);
  out->GetPointData()->SetNormals(source->GetPointData()->GetNormals());
  return out;
}

// A coarse copy of a large mesh for the frames drawn while the camera moves: VTK's quadric
// clustering on a grid of `cell_mm`, with normals from its winding (turned, with the winding
// back, for a mesh whose triangles are wound against their normals: reversed_winding). The
// clustering reads the points and triangles only, not the point data.
vtkSmartPointer<vtkPolyData> coarse_copy(vtkPolyData* full, double cell_mm, bool reversed) {
  double b[6];
  full->GetBounds(b);
  vtkNew<vtkQuadricClustering> cluster;
  cluster->SetInputData(full);
  cluster->SetNumberOfDivisions(std::max(2, static_cast<int>(std::ceil((b[1] - b[0]) / cell_mm))),
                                std::max(2, static_cast<int>(std::ceil((b[3] - b[2]) / cell_mm))),
                                std::max(2, static_cast<int>(std::ceil((b[5] - b[4]) / cell_mm))));
  cluster->AutoAdjustNumberOfDivisionsOff();
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputConnection(cluster->GetOutputPort());
  normals->SplittingOff();
  normals->ConsistencyOff();
  normals->AutoOrientNormalsOff();
  normals->SetFlipNormals(reversed);
  normals->Update();
  vtkSmartPointer<vtkPolyData> out = normals->GetOutput();
  return out;
}

// A mesh actor that converts its mesh only when a different mesh is shown.
struct MeshLayer {
  const void* shown = nullptr;
  std::shared_ptr<const void> keep;  // keeps the shown mesh alive so its address stays unique
  vtkNew<vtkPolyDataMapper> mapper;
  vtkNew<vtkActor> actor;
  // Picking: the plan's own locator of the shown mesh (kept alive with it by `keep`), so the
  // view builds no second search structure (a VTK cell locator of a skull takes several times
  // the plan's own: docs/BENCHMARKS.md, "Where the memory goes, and what bounds it").
  const SurfaceLocator* locator = nullptr;

  MeshLayer() {
    actor->SetMapper(mapper);
    mapper->ScalarVisibilityOff();
  }
  /// `reflection_of`: a layer that may already show this mesh, to be drawn here with a
  /// reflection (the mirror is the skull, reflected and moved): its points and normals are
  /// shared rather than the mesh converted a second time.
  void show(const SkullMesh* mesh, std::shared_ptr<const void> owner,
            const SurfaceLocator* mesh_locator = nullptr,
            const MeshLayer* reflection_of = nullptr) {
    if (!mesh) {
      actor->SetVisibility(false);
      shown = nullptr;
      locator = nullptr;
      keep.reset();
      return;
    }
    if (mesh != shown) {
      vtkSmartPointer<vtkPolyData> poly = to_polydata_or_shared(*mesh, reflection_of);
      mapper->SetInputData(poly);
      shown = mesh;
      reversed = reflection_of != nullptr;
      actor->SetMapper(mapper);  // a coarse copy is of the mesh shown before, which may go:
      coarse_of = nullptr;       // its address is no name for it once another is shown
    }
    // The owner may be new with the same mesh (the mirror moved): its locator answers now.
    locator = mesh_locator;
    keep = std::move(owner);
    actor->SetVisibility(true);
  }
  /// Shows a mesh already converted (`key` names it, `owner` keeps it alive).
  void show_polydata(const void* key, vtkPolyData* poly, std::shared_ptr<const void> owner) {
    if (key != shown) {
      mapper->SetInputData(poly);
      shown = key;
      reversed = false;
      actor->SetMapper(mapper);
      coarse_of = nullptr;
    }
    locator = nullptr;
    keep = std::move(owner);
    actor->SetVisibility(true);
  }
  static vtkSmartPointer<vtkPolyData> to_polydata_or_shared(const SkullMesh& mesh,
                                                            const MeshLayer* reflection_of) {
    vtkPolyData* shared = reflection_of && reflection_of->shown == &mesh
                              ? vtkPolyData::SafeDownCast(reflection_of->mapper->GetInput())
                              : nullptr;
    if (shared) return reversed_winding(shared);
    vtkSmartPointer<vtkPolyData> poly = to_polydata(mesh);
    return reflection_of ? reversed_winding(poly) : poly;
  }
  /// Draws the mesh moved by `motion` without copying it (the mirror: the skull reflected and
  /// registered, an improper motion; VTK turns the normals with the inverse transpose, so the
  /// reflected surface is lit from the right side).
  void set_motion(const RigidTransform& motion) {
    vtkNew<vtkMatrix4x4> m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) m->SetElement(r, c, motion.rotation(r, c));
      m->SetElement(r, 3, motion.translation(r));
    }
    actor->SetUserMatrix(m);
  }
  bool visible() const { return shown && actor->GetVisibility(); }

  // While the camera moves, a mesh of more than kCoarseAbove triangles is drawn from a coarse
  // copy (coarse_copy, given by set_coarse when made on a worker, else made at the first move
  // after the mesh changed; a reflection of another layer's mesh reverses that layer's copy,
  // as the mesh itself is shared): under Mesa's software renderer a frame of the whole skull
  // and translucent mirror takes several times one of their coarse copies (docs/USER_GUIDE.md,
  // "The window"; docs/BENCHMARKS.md).
  static constexpr vtkIdType kCoarseAbove = 150000;
  static constexpr double kCoarseCellMm = 3.0;
  vtkNew<vtkPolyDataMapper> coarse_mapper;
  const void* coarse_of = nullptr;  // the shown mesh the coarse copy is of
  // The shown triangles are wound against their normals (reversed_winding, for a reflection).
  bool reversed = false;
  void draw_coarse(bool coarse, const MeshLayer* reflection_of = nullptr) {
    vtkPolyData* full = vtkPolyData::SafeDownCast(mapper->GetInput());
    if (!coarse || !shown || !full || full->GetNumberOfPolys() <= kCoarseAbove) {
      actor->SetMapper(mapper);
      return;
    }
    if (coarse_of != shown) {
      vtkPolyData* shared =
          reversed && reflection_of && reflection_of->coarse_of == shown
              ? vtkPolyData::SafeDownCast(reflection_of->coarse_mapper->GetInput())
              : nullptr;
      set_coarse(shared ? reversed_winding(shared) : coarse_copy(full, kCoarseCellMm, reversed));
    }
    coarse_mapper->SetClippingPlanes(mapper->GetClippingPlanes());
    actor->SetMapper(coarse_mapper);
  }
  /// The coarse copy of the mesh shown, made elsewhere (on a worker, before the first move).
  void set_coarse(vtkPolyData* copy) {
    coarse_mapper->SetInputData(copy);
    coarse_mapper->ScalarVisibilityOff();
    coarse_of = shown;
  }
};

// Points drawn as glyphs (markers, landmarks).
struct GlyphLayer {
  vtkNew<vtkPolyData> points_data;
  vtkNew<vtkGlyph3DMapper> mapper;
  vtkNew<vtkActor> actor;

  GlyphLayer(vtkAlgorithm* source, const std::array<double, 3>& color) {
    mapper->SetInputData(points_data);
    mapper->SetSourceConnection(source->GetOutputPort());
    mapper->ScalingOff();
    mapper->ScalarVisibilityOff();
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(color[0], color[1], color[2]);
    actor->GetProperty()->SetSpecular(0.4);
  }
  void set(const std::vector<Eigen::Vector3d>& pts) {
    vtkNew<vtkPoints> p;
    for (const auto& x : pts) p->InsertNextPoint(x.x(), x.y(), x.z());
    points_data->SetPoints(p);
    points_data->Modified();
    actor->SetVisibility(!pts.empty());
  }
  vtkIdType count() const { return points_data->GetNumberOfPoints(); }
};

vtkSmartPointer<vtkAlgorithm> sphere(double radius) {
  vtkNew<vtkSphereSource> s;
  s->SetRadius(radius);
  s->SetThetaResolution(16);
  s->SetPhiResolution(12);
  return s;
}

vtkSmartPointer<vtkAlgorithm> cube(double edge) {
  vtkNew<vtkCubeSource> c;
  c->SetXLength(edge);
  c->SetYLength(edge);
  c->SetZLength(edge);
  return c;
}

constexpr std::array<double, 3> kBone{0.93, 0.90, 0.82};
constexpr std::array<double, 3> kMirror{0.35, 0.80, 0.40};
constexpr std::array<double, 3> kEdge{0.10, 0.75, 0.20};
constexpr std::array<double, 3> kSurface{0.90, 0.20, 0.85};
constexpr std::array<double, 3> kImplant{0.95, 0.70, 0.25};

void setup_orientation_marker(vtkRenderer* r, vtkAnnotatedCubeActor* cube) {
  cube->SetXPlusFaceText("L");
  cube->SetXMinusFaceText("R");
  cube->SetYPlusFaceText("P");
  cube->SetYMinusFaceText("A");
  cube->SetZPlusFaceText("S");
  cube->SetZMinusFaceText("I");
  cube->SetFaceTextScale(0.62);
  cube->GetCubeProperty()->SetColor(0.82, 0.84, 0.88);
  cube->GetTextEdgesProperty()->SetColor(0.2, 0.2, 0.2);
  cube->GetTextEdgesProperty()->SetLineWidth(1.0);
  // Left/right red, anterior/posterior green, superior/inferior blue, as in Slicer and ITK-SNAP.
  for (auto* p : {cube->GetXPlusFaceProperty(), cube->GetXMinusFaceProperty()})
    p->SetColor(0.85, 0.15, 0.15);
  for (auto* p : {cube->GetYPlusFaceProperty(), cube->GetYMinusFaceProperty()})
    p->SetColor(0.15, 0.65, 0.20);
  for (auto* p : {cube->GetZPlusFaceProperty(), cube->GetZMinusFaceProperty()})
    p->SetColor(0.20, 0.35, 0.90);
  r->SetLayer(1);
  r->InteractiveOff();
  r->AddActor(cube);
}

// The marker's camera looks along the main camera's direction, with its up, from a fixed
// distance: the cube turns as the skull does.
void follow_camera(vtkCamera* main, vtkCamera* marker) {
  double dop[3], up[3];
  main->GetDirectionOfProjection(dop);
  main->GetViewUp(up);
  marker->SetFocalPoint(0, 0, 0);
  marker->SetPosition(-4.0 * dop[0], -4.0 * dop[1], -4.0 * dop[2]);
  marker->SetViewUp(up);
  marker->SetViewAngle(30.0);
  marker->SetClippingRange(0.1, 20.0);
}

}  // namespace

struct SkullView::Impl {
  vtkNew<vtkGenericOpenGLRenderWindow> window;
  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkGenericRenderWindowInteractor> interactor;
  vtkNew<vtkInteractorStyleTrackballCamera> style;
  vtkNew<vtkPlane> clip;
  MeshLayer skull, mirror, implant;
  MeshLayer mould_outer, mould_inner;  // a casting mould's halves, opened apart
  GlyphLayer outer_edge{sphere(1.6), kEdge}, inner_edge{cube(2.4), kEdge},
      outer_surface{sphere(1.6), kSurface}, inner_surface{cube(2.4), kSurface},
      landmarks{sphere(2.6), {0.90, 0.15, 0.10}}, selected{sphere(2.8), {1.0, 0.95, 0.1}},
      cursor{sphere(1.8), {0.0, 0.85, 1.0}},         // the slice views' shared cursor
      zones{sphere(1.0), {1.0, 0.55, 0.0}},          // clearance zones, scaled to their radius
      handle_balls{sphere(1.3), {0.15, 0.45, 1.0}},  // tabs and holes that can be dragged
      rim_gap{sphere(2.6), {1.0, 0.02, 0.02}},       // where the implant stands off the bone
      handle_drop{sphere(1.8), {1.0, 0.95, 0.1}};    // where the dragged one would go
  vtkNew<vtkPlaneSource> plane_source;
  vtkNew<vtkPolyDataMapper> plane_mapper;
  vtkNew<vtkActor> plane_actor;
  // The last proposal's unseen stretches of the rim, as lines from rim point to rim point, on
  // a layer above the scene: a chord between rim points runs through the bone's edge and under
  // the translucent mirror, where it would be hidden.
  vtkNew<vtkRenderer> overlay;
  vtkNew<vtkPolyData> unseen_data;
  vtkNew<vtkPolyDataMapper> unseen_mapper;
  vtkNew<vtkActor> unseen_actor;
  // The patient's directions in the lower-left corner: a cube labelled L/R, A/P, S/I in the
  // frame meshes are in (LPS: +x is the patient's left, +y posterior, +z superior), turned with
  // the camera, so a skull that came in reflected or upside down shows at a glance.
  // The thickness map: the implant by its thickness, the skull near it by its gap to it.
  // The implant's locator for clicks on it (holes), made when first needed.
  std::unique_ptr<SurfaceLocator> implant_locator;
  const void* implant_locator_of = nullptr;
  std::shared_ptr<const ThicknessMap> thickness;
  const void* thickness_of = nullptr;  // the implant mesh the map is of
  bool thickness_wanted = false;
  vtkNew<vtkLookupTable> thickness_colors, gap_colors;
  vtkNew<vtkScalarBarActor> thickness_bar, gap_bar;
  vtkNew<vtkRenderer> orientation;
  vtkNew<vtkAnnotatedCubeActor> orientation_cube;
  // The patient's directions at the middle of the view's left, right, top and bottom edges, as
  // radiology viewers show them, following the camera.
  std::array<vtkNew<vtkTextActor>, 4> edge_text;
  // The named landmarks' names beside their balls (nasion, left orbit, right orbit).
  std::array<vtkNew<vtkBillboardTextActor3D>, 3> landmark_names;
  std::array<bool, 3> landmark_named{};  // which of them the plan has
  std::array<std::string, 4> edge_letters;
  bool clip_wanted = false;         // the plan's clip plane applied to the view
  std::optional<Plane> clip_plane;  // the plan's, applied or not

  std::vector<Marker> markers;
  bool mirror_wanted = true, plane_wanted = true, markers_editable = false, camera_set = false;
  bool markers_wanted = true;  // markers, landmarks, handles and zones drawn
  PickTarget target = PickTarget::None;
  int selected_id = 0, drag_id = 0;
  std::optional<Eigen::Vector3d> drag_to;  // where the dragged marker is, while dragged
  std::vector<Handle> handles;
  int handle_id = 0;                         // the handle pressed on (0: none)
  std::optional<Eigen::Vector3d> handle_at;  // where it has been dragged to
  QPoint press_pos;
  bool moved = false;
  bool skull_drawn = false;  // a frame with the skull has been drawn
  // While the camera moves (a drag, a wheel turn) or a marker or handle is dragged, the large
  // meshes are drawn coarse; 250 ms after it stops they are drawn whole again.
  QTimer settle;
  bool dragging = false;  // a marker or a handle is being dragged
  // The skull's coarse copy is made on a worker as soon as a large skull is shown, so the
  // first move does not wait for it; `skull_generation` counts the meshes the skull layer
  // has shown, and a copy is taken only for the mesh it was made of.
  int skull_generation = 0;
  QFutureWatcher<std::pair<int, vtkSmartPointer<vtkPolyData>>> coarse_watcher;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();
  double radius = 100.0;

  double dpr = 1.0;
  int height_px() const { return window->GetSize()[1]; }
  int display_x(const QPoint& p) const { return static_cast<int>(p.x() * dpr); }
  int display_y(const QPoint& p) const { return height_px() - 1 - static_cast<int>(p.y() * dpr); }

  void set_up_layers();
  void set_up_legends();
  void set_up_labels();
};

void SkullView::set_default_surface_format() {
  QSurfaceFormat format;
  format.setVersion(3, 2);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setDepthBufferSize(24);
  format.setStencilBufferSize(8);
  format.setAlphaBufferSize(8);
  format.setSamples(0);
  QSurfaceFormat::setDefaultFormat(format);
}

SkullView::SkullView(QWidget* parent) : QOpenGLWidget(parent), d_(std::make_unique<Impl>()) {
  setMinimumSize(280, 280);
  setFocusPolicy(Qt::StrongFocus);
  Impl& d = *d_;
  d.window->AddRenderer(d.renderer);
  d.interactor->SetRenderWindow(d.window);
  d.interactor->SetInteractorStyle(d.style);
  d.interactor->EnableRenderOff();
  vtkNew<vtkCallbackCommand> on_render;
  on_render->SetClientData(this);
  on_render->SetCallback([](vtkObject*, unsigned long, void* self, void*) {
    static_cast<SkullView*>(self)->update();
  });
  d.interactor->AddObserver(vtkCommand::RenderEvent, on_render);
  d.settle.setSingleShot(true);
  d.settle.setInterval(250);
  connect(&d.settle, &QTimer::timeout, this, [this] {
    set_moving(false);
    update();
  });
  connect(&d.coarse_watcher, &QFutureWatcherBase::finished, this, [this] { take_coarse_copy(); });
  vtkNew<vtkCallbackCommand> on_move;
  on_move->SetClientData(this);
  on_move->SetCallback([](vtkObject*, unsigned long event, void* self, void*) {
    auto* view = static_cast<SkullView*>(self);
    if (event == vtkCommand::StartInteractionEvent) {
      view->d_->settle.stop();
      view->set_moving(true);
    } else {
      view->d_->settle.start();
    }
  });
  d.style->AddObserver(vtkCommand::StartInteractionEvent, on_move);
  d.style->AddObserver(vtkCommand::EndInteractionEvent, on_move);

  d.set_up_layers();
  d.set_up_legends();
  d.set_up_labels();
}

// The renderers' settings and the layers' looks; every layer's actor added, hidden.
void SkullView::Impl::set_up_layers() {
  // Depth peeling for the translucent mirror and plane: order-independent transparency
  // (VTK's default without it) draws wrong colours under Mesa's llvmpipe. Four peels, stopping
  // once fewer than 5 % of the pixels change: hardly a pixel differs from six exact peels, and
  // a frame under llvmpipe takes about half as long (measured with cranioplan --pauses:
  // docs/decisions/0028-speed-history.md).
  window->SetAlphaBitPlanes(1);
  window->SetMultiSamples(0);
  renderer->SetUseDepthPeeling(1);
  renderer->SetMaximumNumberOfPeels(4);
  renderer->SetOcclusionRatio(0.05);
  renderer->GradientBackgroundOn();
  renderer->SetBackground(0.10, 0.11, 0.14);
  renderer->SetBackground2(0.30, 0.33, 0.40);
  skull.actor->GetProperty()->SetColor(kBone[0], kBone[1], kBone[2]);
  skull.actor->GetProperty()->SetSpecular(0.15);
  mirror.actor->GetProperty()->SetColor(kMirror[0], kMirror[1], kMirror[2]);
  mirror.actor->GetProperty()->SetOpacity(0.45);
  implant.actor->GetProperty()->SetColor(kImplant[0], kImplant[1], kImplant[2]);
  implant.actor->GetProperty()->SetSpecular(0.3);
  selected.actor->GetProperty()->SetOpacity(0.55);
  for (MeshLayer* half : {&mould_outer, &mould_inner}) {
    half->actor->GetProperty()->SetColor(0.55, 0.72, 0.90);
    half->actor->GetProperty()->SetOpacity(0.5);
    half->actor->GetProperty()->SetSpecular(0.2);
  }
  plane_actor->SetMapper(plane_mapper);
  plane_mapper->SetInputConnection(plane_source->GetOutputPort());
  plane_actor->GetProperty()->SetColor(0.30, 0.55, 1.0);
  plane_actor->GetProperty()->SetOpacity(0.25);
  window->SetNumberOfLayers(2);
  overlay->SetLayer(1);
  overlay->InteractiveOff();
  overlay->SetActiveCamera(renderer->GetActiveCamera());
  window->AddRenderer(overlay);
  unseen_mapper->SetInputData(unseen_data);
  unseen_actor->SetMapper(unseen_mapper);
  unseen_actor->GetProperty()->SetColor(1.0, 0.45, 0.05);
  unseen_actor->GetProperty()->SetLineWidth(7.0);
  unseen_actor->GetProperty()->SetAmbient(1.0);  // flat: the same orange from any side
  unseen_actor->GetProperty()->SetDiffuse(0.0);
  unseen_actor->GetProperty()->RenderLinesAsTubesOn();
  for (vtkActor* a :
       {skull.actor.Get(), mirror.actor.Get(), implant.actor.Get(), mould_outer.actor.Get(),
        mould_inner.actor.Get(), outer_edge.actor.Get(), inner_edge.actor.Get(),
        outer_surface.actor.Get(), inner_surface.actor.Get(), landmarks.actor.Get(),
        selected.actor.Get(), cursor.actor.Get(), zones.actor.Get(), handle_balls.actor.Get(),
        handle_drop.actor.Get(), plane_actor.Get()}) {
    a->SetVisibility(false);
    renderer->AddActor(a);
  }
  unseen_actor->SetVisibility(false);
  overlay->AddActor(unseen_actor);
  // The rim gap's ball on the same layer: it sits on the implant's edge by the bone, where the
  // bone or the mirror would hide it.
  rim_gap.actor->SetVisibility(false);
  rim_gap.actor->GetProperty()->SetAmbient(0.6);
  overlay->AddActor(rim_gap.actor);
}

// The colour maps of the thickness and the bone's gap, and their legends (hidden).
void SkullView::Impl::set_up_legends() {
  // Thickness 0 (red) to 6 mm (blue); the bone's gap to the implant 0 (white) to 3 mm (dark
  // violet), the bone's colour beyond the map's reach. Both in mm.
  thickness_colors->SetRange(0.0, 6.0);
  thickness_colors->SetHueRange(0.0, 0.66);
  thickness_colors->Build();
  gap_colors->SetRange(0.0, 3.0);
  gap_colors->SetHueRange(0.8, 0.8);
  gap_colors->SetSaturationRange(0.0, 0.9);
  gap_colors->SetValueRange(1.0, 0.45);
  gap_colors->SetNanColor(kBone[0], kBone[1], kBone[2], 1.0);
  gap_colors->Build();
  auto legend = [this](vtkScalarBarActor* bar, vtkLookupTable* lut, const char* title, double x) {
    bar->SetLookupTable(lut);
    bar->SetTitle(title);
    bar->SetNumberOfLabels(4);
    bar->SetLabelFormat("%.1f");
    bar->SetOrientationToVertical();
    bar->SetPosition(x, 0.06);
    bar->SetWidth(0.11);
    bar->SetHeight(0.4);
    bar->SetBarRatio(0.3);           // room for the labels beside the colours
    bar->UnconstrainedFontSizeOn();  // sizes in pixels, not scaled to the bar
    bar->GetTitleTextProperty()->SetFontSize(14);
    bar->GetTitleTextProperty()->BoldOff();
    bar->GetTitleTextProperty()->ItalicOff();
    bar->GetTitleTextProperty()->ShadowOff();
    bar->GetLabelTextProperty()->SetFontSize(13);
    bar->GetLabelTextProperty()->ItalicOff();
    bar->GetLabelTextProperty()->ShadowOff();
    bar->SetVisibility(false);
    overlay->AddActor2D(bar);
  };
  legend(thickness_bar, thickness_colors, "Thickness\n(mm)", 0.87);
  legend(gap_bar, gap_colors, "Bone gap\n(mm)", 0.70);
  for (vtkScalarBarActor* bar : {thickness_bar.Get(), gap_bar.Get()})
    for (vtkTextProperty* t : {bar->GetTitleTextProperty(), bar->GetLabelTextProperty()}) {
      // Light text on a dark card of its own: readable over bone and over the background.
      t->SetColor(1.0, 1.0, 1.0);
      t->SetBackgroundColor(0.0, 0.0, 0.0);
      t->SetBackgroundOpacity(0.75);
    }
}

// The landmarks' names, the patient's directions at the view's edges, the clearance zones'
// balls and the orientation cube.
void SkullView::Impl::set_up_labels() {
  for (vtkBillboardTextActor3D* t : landmark_names) {
    vtkTextProperty* tp = t->GetTextProperty();
    tp->SetFontSize(15);
    tp->BoldOn();
    tp->SetColor(1.0, 1.0, 1.0);
    tp->SetBackgroundColor(0.55, 0.08, 0.05);
    tp->SetBackgroundOpacity(0.8);
    tp->SetJustificationToLeft();
    tp->SetVerticalJustificationToBottom();
    t->SetDisplayOffset(10, 6);
    t->SetVisibility(false);
    overlay->AddActor(t);
  }
  const double edge_at[4][2] = {{0.012, 0.5}, {0.988, 0.5}, {0.5, 0.985}, {0.5, 0.015}};
  for (int k = 0; k < 4; ++k) {
    vtkTextActor* t = edge_text[k];
    t->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    t->SetPosition(edge_at[k][0], edge_at[k][1]);
    vtkTextProperty* tp = t->GetTextProperty();
    tp->SetFontSize(18);
    tp->BoldOn();
    tp->SetColor(1.0, 0.85, 0.25);
    tp->SetJustification(k == 0 ? VTK_TEXT_LEFT : k == 1 ? VTK_TEXT_RIGHT : VTK_TEXT_CENTERED);
    tp->SetVerticalJustification(k == 2   ? VTK_TEXT_TOP
                                 : k == 3 ? VTK_TEXT_BOTTOM
                                          : VTK_TEXT_CENTERED);
    tp->ShadowOn();
    overlay->AddActor2D(t);
  }
  zones.mapper->ScalingOn();
  zones.mapper->SetScaleArray("radius");
  zones.mapper->SetScaleModeToScaleByMagnitude();
  zones.actor->GetProperty()->SetOpacity(0.3);
  setup_orientation_marker(orientation, orientation_cube);
  window->AddRenderer(orientation);
}

SkullView::~SkullView() {
  makeCurrent();
  d_->window->Finalize();
  doneCurrent();
}

void SkullView::initializeGL() {
  Impl& d = *d_;
  d.window->SetOwnContext(false);
  d.window->SetFrameBlitModeToBlitToCurrent();
  d.window->SetIsCurrent(true);
  d.window->SetMapped(1);
  d.window->OpenGLInitContext();
  d.interactor->Initialize();
}

void SkullView::resizeGL(int w, int h) {
  Impl& d = *d_;
  d.dpr = devicePixelRatioF();
  const int pw = static_cast<int>(w * d.dpr), ph = static_cast<int>(h * d.dpr);
  d.window->SetSize(pw, ph);
  d.interactor->UpdateSize(pw, ph);
  const double side = 96.0 * d.dpr;  // the orientation cube's square, pixels
  d.orientation->SetViewport(0.0, 0.0, std::min(1.0, side / std::max(1, pw)),
                             std::min(1.0, side / std::max(1, ph)));
}

void SkullView::paintGL() {
  Impl& d = *d_;
  d.dpr = devicePixelRatioF();
  d.window->SetReadyForRendering(true);
  d.window->SetSize(static_cast<int>(width() * d.dpr), static_cast<int>(height() * d.dpr));
  follow_camera(d.renderer->GetActiveCamera(), d.orientation->GetActiveCamera());
  update_edge_letters();
  // With a mould shown, it and the implant alone: the rest of the scene is hidden while drawn.
  std::vector<vtkActor*> hidden;
  if (d.mould_outer.visible()) {
    vtkActorCollection* actors = d.renderer->GetActors();
    actors->InitTraversal();
    while (vtkActor* a = actors->GetNextActor())
      if (a->GetVisibility() && a != d.implant.actor.Get() && a != d.mould_outer.actor.Get() &&
          a != d.mould_inner.actor.Get()) {
        a->SetVisibility(false);
        hidden.push_back(a);
      }
    for (vtkActor* a : {d.unseen_actor.Get(), d.rim_gap.actor.Get()})
      if (a->GetVisibility()) {
        a->SetVisibility(false);
        hidden.push_back(a);
      }
  }
  d.window->Render();
  for (vtkActor* a : hidden) a->SetVisibility(true);
  d.window->SetReadyForRendering(false);
  if (!d.skull_drawn && d.skull.visible()) {
    d.skull_drawn = true;
    emit skullFirstDrawn();
  }
}

void SkullView::show_state(const PlanState& s) {
  Impl& d = *d_;
  const bool had_skull = d.skull.shown != nullptr;
  const void* skull_before = d.skull.shown;
  d.skull.show(s.skull ? &s.skull->surface->mesh : nullptr,
               s.skull ? std::shared_ptr<const void>(s.skull) : nullptr,
               s.skull ? &s.skull->surface->locator : nullptr);
  if (d.skull.shown != skull_before) {
    ++d.skull_generation;
    if (s.skull && s.skull->surface->mesh.n_faces() > MeshLayer::kCoarseAbove) {
      std::shared_ptr<const SkullInput> skull = s.skull;  // kept alive for the worker
      d.coarse_watcher.setFuture(QtConcurrent::run([skull, generation = d.skull_generation] {
        // The drawn copy's normals are of no use to the clustering.
        const vtkSmartPointer<vtkPolyData> full = bare_polydata(skull->surface->mesh);
        return std::make_pair(generation,
                              coarse_copy(full, MeshLayer::kCoarseCellMm, /*reversed=*/false));
      }));
    }
  }
  d.mirror.show(s.mirrored ? &s.mirrored->skull->mesh : nullptr, s.mirrored,
                s.mirrored ? &s.mirrored->locator : nullptr, &d.skull);
  if (s.mirrored) d.mirror.set_motion(s.mirrored->placement);
  d.mirror.actor->SetVisibility(d.mirror.shown && d.mirror_wanted);
  d.implant.show(s.implant ? &s.implant->result().mesh : nullptr, s.implant);
  if (d.thickness_wanted) set_thickness_visible(true);  // off until the new implant's map
  if (d.implant.shown != d.implant_locator_of) {        // made again for the next click on it
    d.implant_locator.reset();
    d.implant_locator_of = nullptr;
  }

  // The plan's clip plane, applied when the view is asked to (step 4, or the toggle).
  d.clip_plane = s.clip_plane;
  set_clip_enabled(d.clip_wanted);

  d.markers = s.markers;
  std::array<std::vector<Eigen::Vector3d>, 4> by_type;
  for (const auto& m : s.markers) by_type[static_cast<int>(m.type)].push_back(m.position);
  d.outer_edge.set(by_type[0]);
  d.inner_edge.set(by_type[1]);
  d.outer_surface.set(by_type[2]);
  d.inner_surface.set(by_type[3]);
  std::vector<Eigen::Vector3d> lm;
  for (const auto* p : {&s.landmarks.nasion, &s.landmarks.orbit_left, &s.landmarks.orbit_right})
    if (*p) lm.push_back(**p);
  lm.insert(lm.end(), s.landmarks.midline.begin(), s.landmarks.midline.end());
  d.landmarks.set(lm);
  {
    const std::pair<const std::optional<Eigen::Vector3d>*, const char*> named[] = {
        {&s.landmarks.nasion, "nasion"},
        {&s.landmarks.orbit_left, "left orbit"},
        {&s.landmarks.orbit_right, "right orbit"}};
    for (int k = 0; k < 3; ++k) {
      vtkBillboardTextActor3D* t = d.landmark_names[k];
      const auto& at = *named[k].first;
      d.landmark_named[k] = at.has_value();
      t->SetVisibility(at.has_value() && d.markers_wanted);
      if (!at) continue;
      t->SetInput(named[k].second);
      t->SetPosition(at->x(), at->y(), at->z());
    }
  }
  // The implant's clearance zones: translucent balls of their radius on the rim.
  std::vector<Eigen::Vector3d> zone_centres;
  vtkNew<vtkDoubleArray> zone_radii;
  zone_radii->SetName("radius");
  if (s.implant_params)
    for (const ClearanceZone& z : s.implant_params->clearance_zones) {
      zone_centres.push_back(z.center);
      zone_radii->InsertNextValue(z.radius_mm);
    }
  d.zones.set(zone_centres);
  d.zones.points_data->GetPointData()->AddArray(zone_radii);
  set_selected_marker(s.find_marker(d.selected_id) ? d.selected_id : 0);
  {
    vtkNew<vtkPoints> points;
    vtkNew<vtkCellArray> lines;
    for (const RimStretch& g : s.unseen_rim) {
      const vtkIdType ids[2] = {points->InsertNextPoint(g.from.data()),
                                points->InsertNextPoint(g.to.data())};
      lines->InsertNextCell(2, ids);
    }
    d.unseen_data->SetPoints(points);
    d.unseen_data->SetLines(lines);
    d.unseen_data->Modified();
    d.unseen_actor->SetVisibility(!s.unseen_rim.empty());
  }

  if (s.skull) {
    double b[6];
    d.skull.mapper->GetInput()->GetBounds(b);
    d.center = Eigen::Vector3d((b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2);
    d.radius = 0.5 * Eigen::Vector3d(b[1] - b[0], b[3] - b[2], b[5] - b[4]).norm();
  }
  if (s.plane && s.skull) {
    const Eigen::Vector3d n = s.plane->normal;
    const Eigen::Vector3d c = s.plane->project(d.center);
    Eigen::Vector3d u = n.unitOrthogonal();
    // In-plane axes along the skull's vertical where possible.
    const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
    if ((z - z.dot(n) * n).norm() > 0.3) u = (z - z.dot(n) * n).normalized();
    const Eigen::Vector3d v = n.cross(u);
    const double h = 1.1 * d.radius;
    const Eigen::Vector3d o = c - h * u - h * v, p1 = c + h * u - h * v, p2 = c - h * u + h * v;
    d.plane_source->SetOrigin(o.x(), o.y(), o.z());
    d.plane_source->SetPoint1(p2.x(), p2.y(), p2.z());
    d.plane_source->SetPoint2(p1.x(), p1.y(), p1.z());
    d.plane_actor->SetVisibility(d.plane_wanted);
  } else {
    d.plane_actor->SetVisibility(false);
  }
  if (s.skull && (!had_skull || !d.camera_set)) {
    set_standard_view(StandardView::Front);
    d.camera_set = true;
  }
  if (!s.skull) d.camera_set = false;
  if (!d.markers_wanted) set_markers_visible(false);
  update();
}

void SkullView::take_coarse_copy() {
  Impl& d = *d_;
  if (d.coarse_watcher.future().isCanceled() || !d.coarse_watcher.isFinished() ||
      d.coarse_watcher.future().resultCount() == 0)
    return;
  const auto [generation, copy] = d.coarse_watcher.result();
  if (generation == d.skull_generation && d.skull.coarse_of != d.skull.shown)
    d.skull.set_coarse(copy);
}

void SkullView::wait_for_coarse_copies() {
  d_->coarse_watcher.waitForFinished();
  take_coarse_copy();
}

void SkullView::set_moving(bool moving) {
  Impl& d = *d_;
  // The implant, what the plan is about, is always drawn whole. Depth peeling (the translucent
  // mirror's true colours) is left for the frames at rest: under llvmpipe it doubles a coarse
  // frame (docs/BENCHMARKS.md, "Turning the view"); blended without it the mirror shows paler
  // while moving.
  d.skull.draw_coarse(moving);
  d.mirror.draw_coarse(moving, &d.skull);
  for (MeshLayer* half : {&d.mould_outer, &d.mould_inner}) half->draw_coarse(moving);
  d.renderer->SetUseDepthPeeling(!moving);
}

std::vector<double> SkullView::time_turn(int frames, bool moving) {
  Impl& d = *d_;
  std::vector<double> ms;
  QElapsedTimer clock;
  clock.start();
  set_moving(moving);
  if (moving) ms.push_back(1e-6 * static_cast<double>(clock.nsecsElapsed()));
  for (int k = 0; k < frames; ++k) {
    d.renderer->GetActiveCamera()->Azimuth(360.0 / std::max(1, frames));
    d.renderer->ResetCameraClippingRange();
    clock.restart();
    grabFramebuffer();
    ms.push_back(1e-6 * static_cast<double>(clock.nsecsElapsed()));
  }
  set_moving(false);
  update();
  return ms;
}

void SkullView::set_mirror_visible(bool visible) {
  d_->mirror_wanted = visible;
  d_->mirror.actor->SetVisibility(visible && d_->mirror.shown);
  update();
}

void SkullView::set_mirror_opacity(double opacity) {
  d_->mirror.actor->GetProperty()->SetOpacity(opacity);
  update();
}

void SkullView::set_plane_visible(bool visible) {
  d_->plane_wanted = visible;
  d_->plane_actor->SetVisibility(visible && d_->plane_actor->GetVisibility());
  update();
}

void SkullView::set_standard_view(StandardView view) {
  Impl& d = *d_;
  // Patient coordinates (LPS): +x the patient's left, +y posterior, +z superior.
  Eigen::Vector3d dir = -Eigen::Vector3d::UnitY(), up = Eigen::Vector3d::UnitZ();
  switch (view) {
    case StandardView::Front:
      dir = -Eigen::Vector3d::UnitY();
      break;
    case StandardView::Back:
      dir = Eigen::Vector3d::UnitY();
      break;
    case StandardView::Left:
      dir = Eigen::Vector3d::UnitX();
      break;
    case StandardView::Right:
      dir = -Eigen::Vector3d::UnitX();
      break;
    case StandardView::Top:
      dir = Eigen::Vector3d::UnitZ();
      up = -Eigen::Vector3d::UnitY();
      break;
  }
  vtkCamera* cam = d.renderer->GetActiveCamera();
  cam->SetViewAngle(30.0);  // the zoom is set anew below
  const Eigen::Vector3d pos = d.center + 4.0 * d.radius * dir;
  cam->SetFocalPoint(d.center.data());
  cam->SetPosition(pos.x(), pos.y(), pos.z());
  cam->SetViewUp(up.x(), up.y(), up.z());
  // The skull framed (not the plane's square, nor the markers): ResetCamera fits the bounding
  // sphere of the bounds, and the skull fills more of the view zoomed by 1.5.
  double b[6];
  if (!d.skull.shown) {
    d.renderer->ResetCamera();
    cam->Zoom(1.5);
    d.renderer->ResetCameraClippingRange();
    update();
    return;
  }
  d.skull.mapper->GetInput()->GetBounds(b);
  d.renderer->ResetCamera(b);
  // The skull's box as the camera sees it, fitted in both the view's width and its height with
  // a margin (ResetCamera fits the box's bounding sphere, which leaves the skull small).
  const Eigen::Vector3d right = dir.cross(up).normalized();
  double half_w = 0.0, half_h = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Eigen::Vector3d p(b[corner & 1], b[2 + ((corner >> 1) & 1)], b[4 + ((corner >> 2) & 1)]);
    half_w = std::max(half_w, std::abs((p - d.center).dot(right)));
    half_h = std::max(half_h, std::abs((p - d.center).dot(up)));
  }
  const double distance = cam->GetDistance();
  const double visible_h = distance * std::tan(0.5 * cam->GetViewAngle() * M_PI / 180.0);
  const double aspect = height() > 0 ? static_cast<double>(width()) / height() : 1.0;
  const double fit = 0.92 * std::min(visible_h / std::max(half_h, 1e-6),
                                     visible_h * aspect / std::max(half_w, 1e-6));
  cam->Zoom(std::clamp(fit, 0.2, 5.0));
  d.renderer->ResetCameraClippingRange();
  update();
}

void SkullView::reset_camera() { set_standard_view(StandardView::Front); }

std::string patient_direction_letters(const Eigen::Vector3d& direction) {
  // LPS: +x the patient's left, +y posterior, +z superior. The largest component's letter,
  // then the next one's when it is more than 22.5° worth (as "LA", "SR"...).
  static const char* const kPlus[] = {"L", "P", "S"};
  static const char* const kMinus[] = {"R", "A", "I"};
  const Eigen::Vector3d d = direction.normalized();
  std::array<int, 3> order{0, 1, 2};
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return std::abs(d[a]) > std::abs(d[b]); });
  std::string out = d[order[0]] >= 0 ? kPlus[order[0]] : kMinus[order[0]];
  if (std::abs(d[order[1]]) > std::sin(22.5 * M_PI / 180.0))
    out += d[order[1]] >= 0 ? kPlus[order[1]] : kMinus[order[1]];
  return out;
}

void SkullView::update_edge_letters() {
  Impl& d = *d_;
  vtkCamera* cam = d.renderer->GetActiveCamera();
  double dop[3], up[3];
  cam->GetDirectionOfProjection(dop);
  cam->GetViewUp(up);
  const Eigen::Vector3d forward(dop[0], dop[1], dop[2]);
  Eigen::Vector3d upward(up[0], up[1], up[2]);
  upward = (upward - upward.dot(forward) * forward).normalized();
  const Eigen::Vector3d right = forward.cross(upward).normalized();
  d.edge_letters = {patient_direction_letters(-right), patient_direction_letters(right),
                    patient_direction_letters(upward), patient_direction_letters(-upward)};
  const bool any = d.skull.shown != nullptr;
  for (int k = 0; k < 4; ++k) {
    d.edge_text[k]->SetInput(d.edge_letters[k].c_str());
    d.edge_text[k]->SetVisibility(any);
  }
}

std::array<double, 10> SkullView::camera() const {
  vtkCamera* cam = d_->renderer->GetActiveCamera();
  std::array<double, 10> c{};
  cam->GetPosition(c.data());
  cam->GetFocalPoint(c.data() + 3);
  cam->GetViewUp(c.data() + 6);
  c[9] = cam->GetViewAngle();
  return c;
}

void SkullView::set_camera(const std::array<double, 10>& c) {
  vtkCamera* cam = d_->renderer->GetActiveCamera();
  cam->SetPosition(c.data());
  cam->SetFocalPoint(c.data() + 3);
  cam->SetViewUp(c.data() + 6);
  cam->SetViewAngle(c[9]);
  d_->renderer->ResetCameraClippingRange();
  update();
}

std::array<std::string, 4> SkullView::edge_letters() {
  update_edge_letters();
  return d_->edge_letters;
}

void SkullView::set_clip_enabled(bool enabled) {
  Impl& d = *d_;
  d.clip_wanted = enabled;
  d.skull.mapper->RemoveAllClippingPlanes();
  d.mirror.mapper->RemoveAllClippingPlanes();
  if (enabled && d.clip_plane) {  // keep the side the normal points away from
    const Eigen::Vector3d keep = -d.clip_plane->normal;
    d.clip->SetNormal(keep.x(), keep.y(), keep.z());
    const Eigen::Vector3d origin = d.clip_plane->normal * d.clip_plane->offset;
    d.clip->SetOrigin(origin.x(), origin.y(), origin.z());
    d.skull.mapper->AddClippingPlane(d.clip);
    d.mirror.mapper->AddClippingPlane(d.clip);
  }
  update();
}

bool SkullView::clip_shown() const {
  return d_->skull.mapper->GetClippingPlanes() &&
         d_->skull.mapper->GetClippingPlanes()->GetNumberOfItems() > 0;
}

void SkullView::look_at_markers() {
  Impl& d = *d_;
  if (d.markers.empty()) return;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& m : d.markers) c += m.position;
  c /= static_cast<double>(d.markers.size());
  Eigen::Vector3d dir = c - d.center;
  if (dir.norm() < 1e-6) return;
  dir.normalize();
  const Eigen::Vector3d up = std::abs(dir.z()) > 0.9 ? Eigen::Vector3d(-Eigen::Vector3d::UnitY())
                                                     : Eigen::Vector3d::UnitZ();
  vtkCamera* cam = d.renderer->GetActiveCamera();
  cam->SetViewAngle(20.0);  // as after a standard view's 1.5× zoom, whatever the view had before
  const Eigen::Vector3d pos = c + 2.6 * d.radius * dir;
  cam->SetFocalPoint(c.x(), c.y(), c.z());
  cam->SetPosition(pos.x(), pos.y(), pos.z());
  cam->SetViewUp(up.x(), up.y(), up.z());
  d.renderer->ResetCameraClippingRange();
  update();
}

void SkullView::look_at_implant(std::optional<StandardView> from) {
  Impl& d = *d_;
  if (!d.implant.shown) return;
  double b[6];
  d.implant.mapper->GetInput()->GetBounds(b);
  const Eigen::Vector3d c((b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2);
  if (from) {
    set_standard_view(*from);
  } else {
    // Along the defect: from outside the skull through the implant's middle.
    Eigen::Vector3d dir = c - d.center;
    if (dir.norm() < 1e-6) dir = -Eigen::Vector3d::UnitY();
    dir.normalize();
    const Eigen::Vector3d up = std::abs(dir.z()) > 0.9 ? Eigen::Vector3d(-Eigen::Vector3d::UnitY())
                                                       : Eigen::Vector3d::UnitZ();
    vtkCamera* cam = d.renderer->GetActiveCamera();
    const Eigen::Vector3d pos = c + 4.0 * d.radius * dir;
    cam->SetFocalPoint(c.x(), c.y(), c.z());
    cam->SetPosition(pos.x(), pos.y(), pos.z());
    cam->SetViewUp(up.x(), up.y(), up.z());
  }
  d.renderer->GetActiveCamera()->SetViewAngle(30.0);
  // The implant and the bone around it fill the view: its bounds grown by half on each side.
  double around[6];
  for (int k = 0; k < 3; ++k) {
    const double half = 0.5 * (b[2 * k + 1] - b[2 * k]);
    around[2 * k] = b[2 * k] - 0.5 * half - 10.0;
    around[2 * k + 1] = b[2 * k + 1] + 0.5 * half + 10.0;
  }
  d.renderer->ResetCamera(around);
  d.renderer->ResetCameraClippingRange();
  update();
}

void SkullView::set_markers_visible(bool visible) {
  Impl& d = *d_;
  d.markers_wanted = visible;
  for (GlyphLayer* g : {&d.outer_edge, &d.inner_edge, &d.outer_surface, &d.inner_surface,
                        &d.landmarks, &d.selected, &d.handle_balls, &d.zones})
    g->actor->SetVisibility(visible && g->count() > 0);
  d.unseen_actor->SetVisibility(visible && d.unseen_data->GetNumberOfCells() > 0);
  for (int k = 0; k < 3; ++k) d.landmark_names[k]->SetVisibility(visible && d.landmark_named[k]);
  update();
}

int SkullView::landmark_names_shown() const {
  int n = 0;
  for (const vtkBillboardTextActor3D* t : d_->landmark_names)
    n += const_cast<vtkBillboardTextActor3D*>(t)->GetVisibility() != 0;
  return n;
}

void SkullView::set_pick_target(PickTarget target) { d_->target = target; }

void SkullView::set_markers_editable(bool editable) { d_->markers_editable = editable; }

void SkullView::set_selected_marker(int id) {
  Impl& d = *d_;
  d.selected_id = 0;
  std::vector<Eigen::Vector3d> p;
  for (const auto& m : d.markers)
    if (m.id == id) {
      d.selected_id = id;
      p.push_back(m.position);
    }
  d.selected.set(p);
  update();
}

namespace {

// `values` as the named point array of the layer's polydata, coloured through `lut` (none:
// the layer's own colour).
void colour_by(MeshLayer& layer, const char* name, const std::vector<float>* values,
               vtkLookupTable* lut) {
  vtkPolyData* poly = vtkPolyData::SafeDownCast(layer.mapper->GetInput());
  if (!values || !poly || static_cast<size_t>(poly->GetNumberOfPoints()) != values->size()) {
    layer.mapper->ScalarVisibilityOff();
    return;
  }
  vtkNew<vtkFloatArray> a;
  a->SetName(name);
  a->SetNumberOfValues(static_cast<vtkIdType>(values->size()));
  for (size_t i = 0; i < values->size(); ++i) a->SetValue(static_cast<vtkIdType>(i), (*values)[i]);
  poly->GetPointData()->AddArray(a);
  layer.mapper->SetLookupTable(lut);
  layer.mapper->UseLookupTableScalarRangeOn();
  layer.mapper->SetScalarModeToUsePointFieldData();
  layer.mapper->SelectColorArray(name);
  layer.mapper->ScalarVisibilityOn();
}

}  // namespace

void SkullView::set_thickness_map(const SkullMesh* implant,
                                  std::shared_ptr<const ThicknessMap> map) {
  d_->thickness = std::move(map);
  d_->thickness_of = implant;
  // The colours span 0 to 6 mm, or to the implant's thickest (rounded up) when it is thicker:
  // the legend's top is then the thickest there is.
  const double top = d_->thickness ? std::max(6.0, std::ceil(d_->thickness->max_mm)) : 6.0;
  d_->thickness_colors->SetRange(0.0, top);
  d_->thickness_colors->Build();
  set_thickness_visible(d_->thickness_wanted);
}

struct SkullView::PreparedMould {
  std::shared_ptr<const MouldResult> mould;
  vtkSmartPointer<vtkPolyData> outer, inner;
  double apart = 0.0;  // each half's shift off the implant along the pull, mm
};

std::shared_ptr<const SkullView::PreparedMould> SkullView::prepare_mould(
    std::shared_ptr<const MouldResult> mould) {
  auto p = std::make_shared<PreparedMould>();
  p->mould = std::move(mould);
  if (!p->mould || !p->mould->usable()) return p;
  p->outer = to_polydata(p->mould->outer);
  p->inner = to_polydata(p->mould->inner);
  // Both halves moved off the implant along the pull, by half the deeper one's depth and 10 mm
  // more: the cavities and the implant between them show.
  const auto depth = [&](const SkullMesh& half) {
    double lo = 1e300, hi = -1e300;
    for (auto vh : half.vertices()) {
      const double h = to_eigen(half.point(vh)).dot(p->mould->axis);
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
    return hi - lo;
  };
  p->apart = 0.5 * std::max(depth(p->mould->outer), depth(p->mould->inner)) + 10.0;
  return p;
}

const MouldResult& SkullView::result_of(const PreparedMould& prepared) { return *prepared.mould; }

void SkullView::set_mould(std::shared_ptr<const PreparedMould> mould) {
  Impl& d = *d_;
  if (!mould || !mould->outer || !mould->inner) {
    d.mould_outer.show(nullptr, nullptr);
    d.mould_inner.show(nullptr, nullptr);
    update();
    return;
  }
  const Eigen::Vector3d axis = mould->mould->axis;
  d.mould_outer.show_polydata(mould->outer.Get(), mould->outer, mould);
  d.mould_inner.show_polydata(mould->inner.Get(), mould->inner, mould);
  d.mould_outer.set_motion({Eigen::Matrix3d::Identity(), mould->apart * axis});
  d.mould_inner.set_motion({Eigen::Matrix3d::Identity(), -mould->apart * axis});
  // Seen from the side, across the pull (the side nearest the present view), pull upwards.
  vtkCamera* camera = d.renderer->GetActiveCamera();
  Eigen::Vector3d toward;
  camera->GetDirectionOfProjection(toward.data());
  toward -= toward.dot(axis) * axis;
  if (toward.norm() < 1e-6) toward = axis.unitOrthogonal();
  toward.normalize();
  const Eigen::Vector3d centre =
      0.5 * (vertex_centroid(mould->mould->inner) + vertex_centroid(mould->mould->outer));
  const Eigen::Vector3d eye = centre - 100.0 * toward;
  camera->SetFocalPoint(centre.x(), centre.y(), centre.z());
  camera->SetPosition(eye.x(), eye.y(), eye.z());
  camera->SetViewUp(axis.x(), axis.y(), axis.z());
  double bounds[6], inner[6];
  d.mould_outer.actor->GetBounds(bounds);
  d.mould_inner.actor->GetBounds(inner);
  for (int k = 0; k < 3; ++k) {
    bounds[2 * k] = std::min(bounds[2 * k], inner[2 * k]);
    bounds[2 * k + 1] = std::max(bounds[2 * k + 1], inner[2 * k + 1]);
  }
  d.renderer->ResetCamera(bounds);
  camera->Zoom(1.4);  // ResetCamera fits the bounding sphere
  d.renderer->ResetCameraClippingRange();
  update();
}

bool SkullView::mould_shown() const { return d_->mould_outer.visible(); }

void SkullView::set_thickness_visible(bool visible) {
  Impl& d = *d_;
  d.thickness_wanted = visible;
  const bool on = visible && d.thickness && d.implant.shown && d.implant.shown == d.thickness_of;
  colour_by(d.implant, "thickness", on ? &d.thickness->implant_mm : nullptr, d.thickness_colors);
  const bool gap = on && !d.thickness->skull_gap_mm.empty();
  colour_by(d.skull, "gap", gap ? &d.thickness->skull_gap_mm : nullptr, d.gap_colors);
  d.thickness_bar->SetVisibility(on);
  d.gap_bar->SetVisibility(gap);
  update();
}

bool SkullView::thickness_shown() const { return d_->thickness_bar->GetVisibility(); }

void SkullView::set_handles(std::vector<Handle> handles) {
  Impl& d = *d_;
  d.handles = std::move(handles);
  std::vector<Eigen::Vector3d> at;
  for (const Handle& h : d.handles) at.push_back(h.position);
  d.handle_balls.set(at);
  d.handle_drop.set({});
  d.handle_id = 0;
  update();
}

int SkullView::handles_shown() const {
  return d_->handle_balls.actor->GetVisibility()
             ? static_cast<int>(d_->handle_balls.points_data->GetNumberOfPoints())
             : 0;
}

void SkullView::set_cursor(const std::optional<Eigen::Vector3d>& point) {
  d_->cursor.set(point ? std::vector<Eigen::Vector3d>{*point} : std::vector<Eigen::Vector3d>{});
  update();
}

int SkullView::coarse_layers_drawn() const {
  const Impl& d = *d_;
  int n = 0;
  for (const MeshLayer* layer : {&d.skull, &d.mirror, &d.implant, &d.mould_outer, &d.mould_inner})
    n += layer->visible() && layer->actor->GetMapper() == layer->coarse_mapper.Get();
  return n;
}

void SkullView::set_rim_gap(const std::optional<Eigen::Vector3d>& at) {
  d_->rim_gap.set(at ? std::vector<Eigen::Vector3d>{*at} : std::vector<Eigen::Vector3d>{});
  update();
}

bool SkullView::rim_gap_shown() const { return d_->rim_gap.actor->GetVisibility(); }

int SkullView::unseen_rim_shown() const {
  return d_->unseen_actor->GetVisibility() ? static_cast<int>(d_->unseen_data->GetNumberOfLines())
                                           : 0;
}

int SkullView::selected_marker() const { return d_->selected_id; }

std::optional<QPoint> SkullView::project(const Eigen::Vector3d& world) {
  Impl& d = *d_;
  vtkNew<vtkCoordinate> c;
  c->SetCoordinateSystemToWorld();
  c->SetValue(world.x(), world.y(), world.z());
  const double* px = c->GetComputedDoubleDisplayValue(d.renderer);
  const double x = px[0] / d.dpr, y = (d.height_px() - 1 - px[1]) / d.dpr;
  if (x < 0 || y < 0 || x >= width() || y >= height()) return std::nullopt;
  return QPoint(static_cast<int>(std::lround(x)), static_cast<int>(std::lround(y)));
}

std::optional<Eigen::Vector3d> SkullView::pick(const QPoint& position, PickTarget target) {
  Impl& d = *d_;
  MeshLayer* layer = target == PickTarget::Mirrored && d.mirror.shown ? &d.mirror
                     : target == PickTarget::Implant                  ? &d.implant
                                                                      : &d.skull;
  if (target == PickTarget::Implant && layer->shown && d.implant_locator_of != layer->shown) {
    d.implant_locator =
        std::make_unique<SurfaceLocator>(*static_cast<const SkullMesh*>(layer->shown));
    d.implant_locator_of = layer->shown;
  }
  const SurfaceLocator* locator =
      target == PickTarget::Implant ? d.implant_locator.get() : layer->locator;
  if (target == PickTarget::None || !layer->shown || !locator) return std::nullopt;
  // The ray under the cursor, from the near to the far end of the view (a hidden mirror can
  // still take markers).
  const double x = d.display_x(position), y = d.display_y(position);
  auto world = [&](double z) {
    d.renderer->SetDisplayPoint(x, y, z);
    d.renderer->DisplayToWorld();
    double w[4];
    d.renderer->GetWorldPoint(w);
    return Eigen::Vector3d(w[0] / w[3], w[1] / w[3], w[2] / w[3]);
  };
  Eigen::Vector3d from = world(0.0), to = world(1.0);
  // Only what the clip plane keeps can be picked: the segment is cut to the kept side.
  if (layer->mapper->GetClippingPlanes() &&
      layer->mapper->GetClippingPlanes()->GetNumberOfItems() > 0) {
    double n[3], o[3];
    d.clip->GetNormal(n);
    d.clip->GetOrigin(o);
    const Eigen::Vector3d normal(n[0], n[1], n[2]), origin(o[0], o[1], o[2]);
    const double fa = normal.dot(from - origin), fb = normal.dot(to - origin);
    if (fa < 0 && fb < 0) return std::nullopt;
    const Eigen::Vector3d crossing = from + (to - from) * (fa / (fa - fb));
    if (fa < 0) from = crossing;
    if (fb < 0) to = crossing;
  }
  const auto hit = locator->first_hit(from, to);
  if (!hit) return std::nullopt;
  return hit->point;
}

namespace {

// The item drawn nearest `at` on the screen, within 10 pixels (markers by their position,
// handles by theirs); none: nullptr.
template <class Item>
const Item* drawn_near(SkullView& view, const std::vector<Item>& items, const QPoint& at) {
  const Item* best = nullptr;
  double best_d2 = 10.0 * 10.0;
  for (const Item& item : items) {
    const auto p = view.project(item.position);
    if (!p) continue;
    const double dx = p->x() - at.x(), dy = p->y() - at.y();
    if (dx * dx + dy * dy < best_d2) {
      best_d2 = dx * dx + dy * dy;
      best = &item;
    }
  }
  return best;
}

// The id of the marker drawn nearest `at`, within 10 pixels; 0 for none.
int marker_near(SkullView& view, const std::vector<Marker>& markers, const QPoint& at) {
  const Marker* m = drawn_near(view, markers, at);
  return m ? m->id : 0;
}

}  // namespace

void SkullView::forward_button(QMouseEvent* e, bool press) {
  Impl& d = *d_;
  const QPoint pos = e->position().toPoint();
  d.interactor->SetEventInformationFlipY(d.display_x(pos), static_cast<int>(pos.y() * d.dpr),
                                         e->modifiers() & Qt::ControlModifier,
                                         e->modifiers() & Qt::ShiftModifier);
  vtkGenericRenderWindowInteractor* i = d.interactor;
  switch (e->button()) {
    case Qt::LeftButton:
      press ? i->LeftButtonPressEvent() : i->LeftButtonReleaseEvent();
      break;
    case Qt::RightButton:
      press ? i->RightButtonPressEvent() : i->RightButtonReleaseEvent();
      break;
    case Qt::MiddleButton:
      press ? i->MiddleButtonPressEvent() : i->MiddleButtonReleaseEvent();
      break;
    default:
      break;
  }
}

void SkullView::mousePressEvent(QMouseEvent* e) {
  Impl& d = *d_;
  const QPoint pos = e->position().toPoint();
  d.press_pos = pos;
  d.moved = false;
  if (e->button() == Qt::LeftButton && d.markers_editable) {
    if (const int id = marker_near(*this, d.markers, pos)) {
      d.drag_id = id;
      d.drag_to.reset();
      set_selected_marker(id);
      return;
    }
  }
  if (e->button() == Qt::LeftButton) {
    if (const Handle* h = drawn_near(*this, d.handles, pos)) {
      d.handle_id = h->id;
      d.handle_at.reset();
      return;
    }
  }
  forward_button(e, true);
}

void SkullView::mouseMoveEvent(QMouseEvent* e) {
  Impl& d = *d_;
  const QPoint pos = e->position().toPoint();
  if ((pos - d.press_pos).manhattanLength() > 3) d.moved = true;
  // A marker or a handle dragged redraws the scene at every move, as a turn of the camera
  // does: the large meshes are drawn coarse until the drop (the drag picks on the plan's own
  // surfaces, not on what is drawn).
  if ((d.drag_id || d.handle_id) && d.moved && !d.dragging) {
    d.dragging = true;
    d.settle.stop();
    set_moving(true);
  }
  if (d.drag_id) {
    if (!d.moved) return;
    const Marker* m = nullptr;
    for (const auto& x : d.markers)
      if (x.id == d.drag_id) m = &x;
    if (!m) return;
    const auto p = pick(
        pos, m->surface == MarkerSurface::Mirrored ? PickTarget::Mirrored : PickTarget::Original);
    // A drag slides along the surface: a pick that jumps (through the opening onto the far
    // wall, or off the skull's silhouette) is not followed.
    if (p && (*p - d.drag_to.value_or(m->position)).norm() < 20.0) {
      d.drag_to = *p;
      emit markerDragging(d.drag_id, *p);
    }
    return;
  }
  if (d.handle_id) {
    if (!d.moved) return;
    const Handle* h = nullptr;
    for (const Handle& x : d.handles)
      if (x.id == d.handle_id) h = &x;
    if (!h) return;
    // As a marker: it slides over its surface and does not jump through an opening.
    const auto p = pick(pos, h->surface);
    const Eigen::Vector3d last = d.handle_at.value_or(h->position);
    if (p && (*p - last).norm() < 20.0) {
      d.handle_at = *p;
      d.handle_drop.set({*p});
      update();
    }
    return;
  }
  d.interactor->SetEventInformationFlipY(d.display_x(pos), static_cast<int>(pos.y() * d.dpr),
                                         e->modifiers() & Qt::ControlModifier,
                                         e->modifiers() & Qt::ShiftModifier);
  d.interactor->MouseMoveEvent();
}

void SkullView::mouseReleaseEvent(QMouseEvent* e) {
  Impl& d = *d_;
  const QPoint pos = e->position().toPoint();
  if (d.dragging) {
    d.dragging = false;
    d.settle.start();
  }
  if (d.drag_id) {
    const int id = d.drag_id;
    const std::optional<Eigen::Vector3d> to = d.drag_to;
    d.drag_id = 0;
    d.drag_to.reset();
    if (d.moved) {
      if (to) emit markerDragged(id, *to);
    } else {
      emit markerClicked(id);
    }
    return;
  }
  if (d.handle_id) {
    const int id = d.handle_id;
    const std::optional<Eigen::Vector3d> to = d.handle_at;
    d.handle_id = 0;
    d.handle_at.reset();
    if (d.moved) {
      d.handle_drop.set({});
      update();
      if (to) emit handleDropped(id, *to);
      return;
    }
    // Not moved: a click where it was pressed, below.
  } else {
    forward_button(e, false);
  }
  if (e->button() != Qt::LeftButton || d.moved) return;
  if (const int id = marker_near(*this, d.markers, pos)) {
    set_selected_marker(id);
    emit markerClicked(id);
    return;
  }
  if (d.target != PickTarget::None) {
    if (const auto p = pick(pos, d.target)) {
      emit pointed(*p);
      emit surfaceClicked(*p);
    }
  } else if (const auto p = pick(pos, PickTarget::Original)) {
    emit pointed(*p);
  }
}

void SkullView::wheelEvent(QWheelEvent* e) {
  Impl& d = *d_;
  const QPoint pos = e->position().toPoint();
  d.interactor->SetEventInformationFlipY(d.display_x(pos), static_cast<int>(pos.y() * d.dpr));
  if (e->angleDelta().y() > 0)
    d.interactor->MouseWheelForwardEvent();
  else if (e->angleDelta().y() < 0)
    d.interactor->MouseWheelBackwardEvent();
}

}  // namespace cranioplan::gui
