#include "main_window.h"

#include <QAction>
#include <QActionGroup>
#include <QApplication>
#include <QCloseEvent>
#include <QDateTime>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDir>
#include <QDockWidget>
#include <QFileDialog>
#include <QFileInfo>
#include <QFutureWatcher>
#include <QHeaderView>
#include <QInputDialog>
#include <QKeySequence>
#include <QLabel>
#include <QListWidget>
#include <QMenu>
#include <QMenuBar>
#include <QMessageBox>
#include <QProgressBar>
#include <QPushButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QShortcut>
#include <QSlider>
#include <QStackedWidget>
#include <QStandardPaths>
#include <QStatusBar>
#include <QTabWidget>
#include <QTableWidget>
#include <QTextBrowser>
#include <QTimer>
#include <QToolBar>
#include <QVBoxLayout>
#include <QtConcurrent/QtConcurrent>
#include <atomic>
#include <cmath>

#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/algorithms/io/write_labelmap.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/audit.h"
#include "cranioplan/sessions/marker_files.h"
#include "cranioplan/sessions/plan_files.h"
#include "cranioplan/sessions/sha256.h"
#include "pages/step_pages.h"

namespace cranioplan::gui {

namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }

QPushButton* button(const QString& text, const char* name, QWidget* parent = nullptr) {
  auto* b = new QPushButton(text, parent);
  b->setObjectName(name);
  return b;
}

QString quality_html(const QualityReport& r, const SoftTissueCheck* tissue = nullptr) {
  return q(quality_report_html(r, tissue));
}

// A worker's watcher whose result is of no use now: deleted once its work is done.
void drop_watcher(QFutureWatcherBase* watcher, QObject* receiver) {
  if (!watcher) return;
  QObject::disconnect(watcher, nullptr, receiver, nullptr);
  if (watcher->isRunning())
    QObject::connect(watcher, &QFutureWatcherBase::finished, watcher, &QObject::deleteLater);
  else
    watcher->deleteLater();
}

}  // namespace

MainWindow::MainWindow(QWidget* parent)
    : QMainWindow(parent), controller_(new PlanController(this)), view_(new SkullView(this)) {
  setWindowTitle(tr("Cranioplan"));
  resize(1500, 950);
  slices_ = new SlicePanel(view_, this);
  setCentralWidget(slices_);
  connect(slices_, &SlicePanel::arranged, this, [this](Layout a) { set_layout(a); });
  build_steps_dock();
  build_plan_dock();
  build_menus();

  case_label_ = new QLabel(this);
  step_label_ = new QLabel(this);
  timer_label_ = new QLabel(this);
  progress_ = new QProgressBar(this);
  progress_->setRange(0, 0);
  progress_->setMaximumWidth(180);
  progress_->setVisible(false);
  cancel_ = button(tr("Cancel"), "cancel", this);
  cancel_->setVisible(false);
  statusBar()->addWidget(case_label_);
  statusBar()->addWidget(step_label_);
  statusBar()->addPermanentWidget(progress_);
  statusBar()->addPermanentWidget(cancel_);
  statusBar()->addPermanentWidget(timer_label_);
  connect(cancel_, &QPushButton::clicked, this, [this] {
    controller_->cancel();
    show_message(tr("Cancelled: the plan is unchanged."), false);
  });

  quality_timer_ = new QTimer(this);
  quality_timer_->setSingleShot(true);
  quality_timer_->setInterval(400);
  connect(quality_timer_, &QTimer::timeout, this, &MainWindow::show_quality);

  clock_ = new QTimer(this);
  connect(clock_, &QTimer::timeout, this, &MainWindow::update_timers);
  clock_->start(1000);
  total_timer_.start();
  step_timer_.start();

  connect(controller_, &PlanController::stateChanged, this, &MainWindow::refresh);
  connect(controller_, &PlanController::trialSettled, this, &MainWindow::trial_settled);
  connect(controller_, &PlanController::refused, this,
          [this](const QString& m) { show_message(m, true); });
  connect(controller_, &PlanController::failed, this, [this](const QString& m) {
    show_message(m, true);
    if (interactive_) QMessageBox::warning(this, tr("Cranioplan"), m);
  });
  connect(controller_, &PlanController::busyChanged, this, [this](bool busy, const QString& what) {
    progress_->setVisible(busy);
    cancel_->setVisible(busy);
    if (busy) show_message(what + QStringLiteral("…"), false);
    // While a marker edit is computed the hand goes on: the next edits queue.
    pages_->setEnabled(!busy || controller_->editing());
  });
  connect(view_, &SkullView::surfaceClicked, this, &MainWindow::on_surface_clicked);
  connect(view_, &SkullView::handleDropped, this, [this](int id, const Eigen::Vector3d& p) {
    step_pages_[static_cast<size_t>(controller_->state().current_step - 1)]->handle_dropped(id, p);
  });
  // One cursor: a click on the skull moves the slices there, a click on a slice the 3D cursor.
  connect(view_, &SkullView::pointed, this, [this](const Eigen::Vector3d& p) {
    if (layout_ == Layout::ThreeD) return;
    slices_->set_cursor(p);
    view_->set_cursor(p);
  });
  connect(slices_, &SlicePanel::ctChanged, this, &MainWindow::show_quality);
  connect(slices_, &SlicePanel::cursorMoved, view_,
          [this](const Eigen::Vector3d& p) { view_->set_cursor(p); });
  connect(view_, &SkullView::markerDragged, this, &MainWindow::on_marker_dragged);
  connect(view_, &SkullView::markerDragging, this, [this](int id, const Eigen::Vector3d& p) {
    if (auto preview = controller_->preview_edit(commands::move_marker(id, p)))
      view_->show_state(*preview);
  });
  connect(view_, &SkullView::markerClicked, this, [this](int id) {
    show_message(tr("Marker %1 selected (Del deletes it, drag moves it).").arg(id), false);
  });

  // Keys 0–3 choose the marker type; Del deletes the selected marker.
  for (int t = 0; t < 4; ++t) {
    auto* key = new QShortcut(QKeySequence(Qt::Key_0 + t), this);
    connect(key, &QShortcut::activated, this,
            [this, t] { set_marker_type(static_cast<MarkerType>(t)); });
  }
  controller_->new_session(SessionInfo{}, QString());
  refresh();
}

MainWindow::~MainWindow() = default;

// ---------------------------------------------------------------------------------------------
// Building the window

void MainWindow::build_menus() {
  QMenu* file = menuBar()->addMenu(tr("&File"));
  QAction* open = file->addAction(tr("Open mesh or CT…"), this, [this] {
    const QString path =
        QFileDialog::getOpenFileName(this, tr("Open a skull"), QString(),
                                     tr("Skull (*.stl *.ply *.obj *.off *.vtk *.vtp *.inv3 *.nrrd "
                                        "*.nhdr *.nii *.nii.gz);;All (*)"));
    if (!path.isEmpty()) open_input(path);
  });
  open->setObjectName("openInput");
  QAction* dicom = file->addAction(tr("Open DICOM folder…"), this, [this] {
    const QString dir = QFileDialog::getExistingDirectory(this, tr("Open a DICOM series"));
    if (!dir.isEmpty()) open_input(dir);
  });
  dicom->setObjectName("openDicom");
  QAction* sample = file->addAction(tr("Open the sample case"), this, [this] { open_sample(); });
  sample->setObjectName("openSample");
  file->addSeparator();
  QAction* open_plan = file->addAction(tr("Open session…"), this, [this] {
    const QString path = QFileDialog::getOpenFileName(
        this, tr("Open a plan"), QString(), tr("Cranioplan plan (*.cranioplan.json *.json)"));
    if (!path.isEmpty()) open_session(path);
  });
  open_plan->setShortcut(QKeySequence::Open);
  open_plan->setObjectName("openSession");
  QAction* save = file->addAction(tr("Save session"), this, [this] {
    QString path = session_path_;
    if (path.isEmpty())
      path = QFileDialog::getSaveFileName(this, tr("Save the plan"), default_plan_name(),
                                          tr("Cranioplan plan (*.cranioplan.json *.json)"));
    if (!path.isEmpty()) save_session_to(path);
  });
  save->setShortcut(QKeySequence::Save);
  save->setObjectName("saveSession");
  file->addAction(tr("Save session as…"), this, [this] {
    const QString path =
        QFileDialog::getSaveFileName(this, tr("Save the plan"), default_plan_name(),
                                     tr("Cranioplan plan (*.cranioplan.json *.json)"));
    if (!path.isEmpty()) save_session_to(path);
  });
  recent_menu_ = file->addMenu(tr("Recent files"));
  refresh_recent_menu();
  file->addSeparator();
  add_points_actions(file);
  file->addSeparator();
  QAction* audit = file->addAction(tr("Audit a session (read-only)…"), this, [this] {
    const QString path = QFileDialog::getOpenFileName(
        this, tr("Audit a plan"), QString(), tr("Cranioplan plan (*.cranioplan.json *.json)"));
    if (!path.isEmpty()) open_audit(path);
  });
  audit->setObjectName("audit");
  file->addSeparator();
  file->addAction(tr("Quit"), this, &QWidget::close)->setShortcut(QKeySequence::Quit);

  build_edit_view_menus();
  build_training_help_menus();
}

// Edit (undo, redo, delete, notes) and View (standard views, the mirror and the plane).
// Markers and landmarks in and out: JSON, CSV or 3D Slicer's markups; a mesh plan's CT.
void MainWindow::add_points_actions(QMenu* file) {
  file->addAction(tr("Attach CT…"), this,
                  [this] {
                    const QString path = QFileDialog::getOpenFileName(
                        this, tr("The CT of this skull"), QString(),
                        tr("CT (*.inv3 *.nrrd *.nhdr *.nii *.nii.gz);;All (*)"));
                    if (!path.isEmpty()) attach_ct(path);
                  })
      ->setObjectName("attachCt");
  file->addAction(tr("Attach CT from a DICOM folder…"), this, [this] {
    const QString dir = QFileDialog::getExistingDirectory(this, tr("The CT of this skull"));
    if (!dir.isEmpty()) attach_ct(dir);
  });
  file->addAction(tr("Design report…"), this, [this] {
    const QString path = QFileDialog::getSaveFileName(
        this, tr("Design report for sign-off (HTML; a PDF beside it)"),
        suggested_path(QStringLiteral("design-report.html")), tr("HTML (*.html)"));
    if (!path.isEmpty()) write_design_report(path);
  });
  file->addAction(tr("Export implant over the CT…"), this,
                  [this] {
                    const QString path = QFileDialog::getSaveFileName(
                        this, tr("The implant as a labelmap on the CT's grid"),
                        suggested_path(QStringLiteral("implant.seg.nrrd")),
                        tr("3D Slicer segmentation (*.seg.nrrd);;Labelmap (*.nrrd)"));
                    if (!path.isEmpty()) export_labelmap(path);
                  })
      ->setObjectName("exportLabelmap");
  const QString markers = tr("Markers (*.mrk.json *.json *.csv)");
  const QString landmarks = tr("Landmarks (*.mrk.json *.json)");
  file->addAction(tr("Import markers…"), this,
                  [this, markers] {
                    const QString path = QFileDialog::getOpenFileName(this, tr("Import markers"),
                                                                      QString(), markers);
                    if (!path.isEmpty()) import_markers(path);
                  })
      ->setObjectName("importMarkersMenu");
  file->addAction(tr("Export markers…"), this,
                  [this, markers] {
                    const QString path = QFileDialog::getSaveFileName(
                        this, tr("Export markers"),
                        suggested_path(QStringLiteral("markers.mrk.json")), markers);
                    if (!path.isEmpty()) export_markers(path);
                  })
      ->setObjectName("exportMarkers");
  file->addAction(tr("Import landmarks…"), this,
                  [this, landmarks] {
                    const QString path = QFileDialog::getOpenFileName(this, tr("Import landmarks"),
                                                                      QString(), landmarks);
                    if (!path.isEmpty()) import_landmarks(path);
                  })
      ->setObjectName("importLandmarks");
  file->addAction(tr("Export landmarks…"), this,
                  [this, landmarks] {
                    const QString path = QFileDialog::getSaveFileName(
                        this, tr("Export landmarks"),
                        suggested_path(QStringLiteral("landmarks.mrk.json")), landmarks);
                    if (!path.isEmpty()) export_landmarks(path);
                  })
      ->setObjectName("exportLandmarks");
}

void MainWindow::attach_ct(const QString& path, double threshold) {
  ExtractBoneSurfaceParams import;
  if (QFileInfo(path).isDir() && !choose_dicom_series(path, import)) return;
  import.threshold = threshold;
  push(commands::attach_ct(path.toStdString(), import), tr("Checking the CT against the skull"));
}

bool MainWindow::export_labelmap(const QString& path) {
  const PlanState& s = controller_->state();
  const std::optional<AttachedCt> source = plan_ct(s);
  if (!s.implant || !source) {
    show_message(s.implant ? tr("The plan has no CT: File → Attach CT… gives it one.")
                           : tr("There is no implant to export: build it first (step 7)."),
                 true);
    return false;
  }
  try {
    QApplication::setOverrideCursor(Qt::WaitCursor);
    std::shared_ptr<const Volume> ct = slices_->ct();
    if (!ct) {
      ReadVolumeParams read;
      read.dicom_series = source->import.dicom_series;
      read.patient_frame = source->import.patient_frame;
      ct = std::make_shared<const Volume>(read_volume(source->path, read));
    }
    write_labelmap_nrrd(labelmap_on_grid(s.implant->result().mesh, *ct), *ct, path.toStdString());
    QApplication::restoreOverrideCursor();
  } catch (const Error& e) {
    QApplication::restoreOverrideCursor();
    show_message(QString::fromUtf8(e.what()), true);
    return false;
  }
  show_message(tr("Wrote the implant on the CT's grid to %1").arg(path), false);
  return true;
}

void MainWindow::import_markers(const QString& path) {
  try {
    const std::string file = path.toStdString();
    push(commands::import_markers(read_markers_file(file), file, sha256_file(file)));
  } catch (const Error& e) {
    show_message(QString::fromUtf8(e.what()), true);
  }
}

void MainWindow::import_landmarks(const QString& path) {
  Landmarks lm;
  try {
    lm = read_landmarks_file(path.toStdString());
  } catch (const Error& e) {
    show_message(QString::fromUtf8(e.what()), true);
    return;
  }
  // The file's landmarks replace the plan's, a command each (undo takes them back one by one);
  // when one is refused (far from the skull: another frame) none is kept.
  std::vector<Command> commands_to_push;
  for (const char* name : {"nasion", "orbit_left", "orbit_right", "midline"})
    commands_to_push.push_back(commands::clear_landmark(name));
  const std::pair<const char*, const std::optional<Eigen::Vector3d>*> named[] = {
      {"nasion", &lm.nasion}, {"orbit_left", &lm.orbit_left}, {"orbit_right", &lm.orbit_right}};
  for (const auto& [name, p] : named)
    if (*p) commands_to_push.push_back(commands::set_landmark(name, **p));
  for (const Eigen::Vector3d& p : lm.midline)
    commands_to_push.push_back(commands::set_landmark("midline", p));
  const size_t before = controller_->session().index();
  for (Command& c : commands_to_push)
    if (!controller_->push(std::move(c))) {
      while (controller_->session().index() > before) controller_->undo();
      show_message(tr("%1: the landmarks were not imported.").arg(path), true);
      return;
    }
  show_message(tr("Imported the landmarks of %1").arg(path), false);
}

bool MainWindow::export_markers(const QString& path) {
  try {
    write_markers_file(controller_->state().markers, path.toStdString());
  } catch (const Error& e) {
    show_message(QString::fromUtf8(e.what()), true);
    return false;
  }
  show_message(tr("Wrote %1 markers to %2").arg(controller_->state().markers.size()).arg(path),
               false);
  return true;
}

bool MainWindow::export_landmarks(const QString& path) {
  try {
    write_landmarks_file(controller_->state().landmarks, path.toStdString());
  } catch (const Error& e) {
    show_message(QString::fromUtf8(e.what()), true);
    return false;
  }
  show_message(tr("Wrote the landmarks to %1").arg(path), false);
  return true;
}

void MainWindow::build_edit_view_menus() {
  QMenu* edit = menuBar()->addMenu(tr("&Edit"));
  // Undo and redo say what they did (the state's own message is the old command's).
  undo_ = edit->addAction(tr("Undo"), this, [this] {
    const std::string what = controller_->session().undo_text();
    controller_->undo();
    if (!what.empty()) note_shown(tr("Undone: %1").arg(q(what.substr(what.find(' ') + 1))));
  });
  undo_->setShortcut(QKeySequence(Qt::CTRL | Qt::Key_Z));
  undo_->setObjectName("undo");
  redo_ = edit->addAction(tr("Redo"), this, [this] {
    const std::string what = controller_->session().redo_text();
    controller_->redo();
    if (!what.empty()) note_shown(tr("Redone: %1").arg(q(what.substr(what.find(' ') + 1))));
  });
  redo_->setShortcut(QKeySequence(Qt::CTRL | Qt::SHIFT | Qt::Key_Z));
  redo_->setObjectName("redo");
  edit->addSeparator();
  QAction* del = edit->addAction(tr("Delete selected marker"), this, [this] {
    if (view_->selected_marker()) push(commands::delete_marker(view_->selected_marker()));
  });
  del->setShortcut(QKeySequence::Delete);
  del->setObjectName("deleteMarker");
  edit->addAction(tr("Add a note…"), this, [this] {
    bool ok = false;
    const QString text = QInputDialog::getText(this, tr("Note"), tr("Note for the plan:"),
                                               QLineEdit::Normal, QString(), &ok);
    if (ok && !text.isEmpty()) push(commands::note(text.toStdString()));
  });

  QMenu* view = menuBar()->addMenu(tr("&View"));
  const std::pair<QString, SkullView::StandardView> views[] = {
      {tr("Front"), SkullView::StandardView::Front},
      {tr("Back"), SkullView::StandardView::Back},
      {tr("Left"), SkullView::StandardView::Left},
      {tr("Right"), SkullView::StandardView::Right},
      {tr("Top"), SkullView::StandardView::Top}};
  int key = 0;
  for (const auto& [name, v] : views) {
    QAction* a = view->addAction(name, this, [this, v = v] { view_->set_standard_view(v); });
    a->setShortcut(QKeySequence(Qt::Key_F5 + key++));
  }
  view->addAction(tr("Look at the markers"), this, [this] { view_->look_at_markers(); })
      ->setShortcut(QKeySequence(Qt::Key_F10));
  view->addAction(tr("Reset"), this, [this] { view_->reset_camera(); })
      ->setShortcut(QKeySequence(Qt::Key_Home));
  view->addSeparator();
  show_mirror_ = view->addAction(tr("Show mirrored skull"));
  show_mirror_->setCheckable(true);
  show_mirror_->setChecked(true);
  show_mirror_->setShortcut(QKeySequence(Qt::Key_M));
  connect(show_mirror_, &QAction::toggled, view_, &SkullView::set_mirror_visible);
  connect(show_mirror_, &QAction::toggled, slices_, &SlicePanel::set_mirror_shown);
  show_thickness_ = view->addAction(tr("Thickness map"));
  show_thickness_->setObjectName("thicknessMap");
  show_thickness_->setCheckable(true);
  show_thickness_->setShortcut(QKeySequence(Qt::Key_T));
  show_thickness_->setToolTip(
      tr("The implant coloured by its thickness, the skull around it by "
         "its gap to the implant"));
  connect(show_thickness_, &QAction::toggled, view_, &SkullView::set_thickness_visible);
  QAction* show_plane = view->addAction(tr("Show midsagittal plane"));
  show_plane->setObjectName("showPlane");
  show_plane->setCheckable(true);
  show_plane->setChecked(true);
  connect(show_plane, &QAction::toggled, view_, &SkullView::set_plane_visible);
  // Step 4's clip plane cuts the skulls in step 4, and elsewhere only when asked here.
  clip_ = view->addAction(tr("Clip the skulls"));
  clip_->setObjectName("viewClip");
  clip_->setCheckable(true);
  clip_->setShortcut(QKeySequence(Qt::Key_C));
  clip_->setToolTip(tr("Cut the skulls at step 4's clip plane (on in step 4; C toggles it)"));
  connect(clip_, &QAction::toggled, view_, &SkullView::set_clip_enabled);
  view->addSeparator();
  add_slice_actions(view);

  // The same in sight above the view: the standard views and what is shown.
  QToolBar* bar = addToolBar(tr("View"));
  bar->setObjectName("viewBar");
  bar->setMovable(false);
  bar->setToolButtonStyle(Qt::ToolButtonTextOnly);
  for (QAction* a : view->actions()) {
    if (a->isSeparator() || a->menu()) continue;
    if (a == show_thickness_ || a == show_mirror_ || a == show_plane || a == clip_) continue;
    if (a->shortcut().isEmpty() || a->shortcut()[0].key() < Qt::Key_F5 ||
        a->shortcut()[0].key() > Qt::Key_F9)
      continue;
    bar->addAction(a);  // Front, Back, Left, Right, Top
  }
  bar->addSeparator();
  show_mirror_->setText(tr("Mirror"));
  show_plane->setText(tr("Plane"));
  for (QAction* a : {clip_, show_mirror_, show_plane, show_thickness_}) bar->addAction(a);
  bar->addSeparator();
  if (QAction* four = findChild<QAction*>("layoutFourUp")) bar->addAction(four);
  if (QAction* only = findChild<QAction*>("layout3d")) bar->addAction(only);
}

// The CT slices: the centre's layout, and window/level presets.
void MainWindow::add_slice_actions(QMenu* view) {
  QMenu* layout = view->addMenu(tr("Layout"));
  auto* layouts = new QActionGroup(this);
  const std::tuple<QString, Layout, const char*> modes[] = {
      {tr("3D only"), Layout::ThreeD, "layout3d"},
      {tr("Four-up: 3D and CT slices"), Layout::FourUp, "layoutFourUp"},
      {tr("Axial slice alone"), Layout::Axial, "layoutAxial"},
      {tr("Coronal slice alone"), Layout::Coronal, "layoutCoronal"},
      {tr("Sagittal slice alone"), Layout::Sagittal, "layoutSagittal"}};
  for (const auto& [name, mode, object] : modes) {
    QAction* a = layout->addAction(name, this, [this, mode = mode] { set_layout(mode); });
    a->setObjectName(object);
    a->setCheckable(true);
    a->setChecked(mode == layout_);
    layouts->addAction(a);
  }
  QAction* markers = view->addAction(tr("Markers on the CT slices"));
  markers->setObjectName("slicesMarkers");
  markers->setCheckable(true);
  markers->setChecked(false);  // the implant's outline is what the slices are looked at for
  connect(markers, &QAction::toggled, slices_, &SlicePanel::set_markers_shown);
  QMenu* wl = view->addMenu(tr("CT window"));
  const std::tuple<QString, SlicePanel::Preset, const char*> presets[] = {
      {tr("Bone (W 1000, L 400)"), SlicePanel::Preset::Bone, "windowBone"},
      {tr("Soft tissue (W 400, L 40)"), SlicePanel::Preset::SoftTissue, "windowSoftTissue"},
      {tr("Brain (W 80, L 40)"), SlicePanel::Preset::Brain, "windowBrain"}};
  for (const auto& [name, preset, object] : presets)
    wl->addAction(name, this, [this, preset = preset] {
        slices_->apply_preset(preset);
      })->setObjectName(object);
}

void MainWindow::set_layout(Layout layout) {
  // Laying out the slices (their outlines of the skull) and drawing the 3D view again take a
  // second or two on a large skull: said, and the pointer waits.
  const bool slow = layout != layout_ && layout != Layout::ThreeD;
  if (slow) {
    QApplication::setOverrideCursor(Qt::WaitCursor);
    show_message(tr("Laying out the views…"), false);
    statusBar()->repaint();
  }
  layout_ = layout;
  slices_->arrange(layout);
  const char* names[] = {"layout3d",      "layoutFourUp",   "layoutAxial",
                         "layoutCoronal", "layoutSagittal", "layout3d"};
  if (auto* a = findChild<QAction*>(names[static_cast<int>(layout)])) a->setChecked(true);
  if (layout == Layout::ThreeD) {
    view_->set_cursor(std::nullopt);
    return;
  }
  slices_->show_state(controller_->state());
  view_->set_cursor(slices_->cursor());
  if (slow) {
    // Until the views have been drawn; clicks given meanwhile wait for them.
    QTimer::singleShot(0, this, [] { QApplication::restoreOverrideCursor(); });
  }
}

// Training (a reference plan and the report) and Help (About).
void MainWindow::build_training_help_menus() {
  QMenu* training = menuBar()->addMenu(tr("&Training"));
  training->addAction(tr("Start training with a reference plan…"), this, [this] {
    const QString path = QFileDialog::getOpenFileName(
        this, tr("The expert's plan"), QString(), tr("Cranioplan plan (*.cranioplan.json *.json)"));
    if (!path.isEmpty()) start_training(path);
  });
  training->addAction(tr("Show the training report"), this, [this] {
    finish_training_if_done();
    show_training_report();
  });

  QMenu* help = menuBar()->addMenu(tr("&Help"));
  QAction* about = help->addAction(tr("About Cranioplan"), this, [this] {
    QMessageBox::about(
        this, tr("About Cranioplan"),
        tr("<h3>Cranioplan %1</h3>"
           "<p>Plan a patient-specific cranial implant from a CT or a skull mesh, step by "
           "step.</p>"
           "<p>Every plan is a session of commands: it records this version, and replays, "
           "verifies and audits with <tt>cranioplan-cli</tt>.</p>"
           "<p>Open source under the MIT licence. Not a medical device: every implant must "
           "be checked by a qualified person before it is made.</p>")
            .arg(CRANIOPLAN_VERSION));
  });
  about->setObjectName("about");
}

void MainWindow::show_training_report() {
  if (training_html_.isEmpty()) {
    show_message(tr("No training report yet: start training and finish the plan."), true);
    return;
  }
  QDialog dialog(this);
  dialog.setWindowTitle(tr("Training report"));
  auto* layout = new QVBoxLayout(&dialog);
  auto* text = new QTextBrowser(&dialog);
  text->setHtml(training_html_);
  layout->addWidget(text);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Save | QDialogButtonBox::Close);
  layout->addWidget(buttons);
  connect(buttons, &QDialogButtonBox::rejected, &dialog, &QDialog::reject);
  connect(buttons, &QDialogButtonBox::accepted, &dialog, [this, &dialog] {
    const QString path = QFileDialog::getSaveFileName(&dialog, tr("Save the report"), QString(),
                                                      tr("HTML (*.html)"));
    if (path.isEmpty()) return;
    QFile f(path);
    if (f.open(QIODevice::WriteOnly)) f.write(training_html_.toUtf8());
  });
  dialog.resize(700, 600);
  dialog.exec();
}

void MainWindow::build_steps_dock() {
  auto* dock = new QDockWidget(tr("Steps"), this);
  dock->setObjectName("stepsDock");
  dock->setFeatures(QDockWidget::NoDockWidgetFeatures);
  auto* panel = new QWidget(dock);
  auto* layout = new QVBoxLayout(panel);
  steps_ = new QListWidget(panel);
  steps_->setObjectName("steps");
  for (const auto& s : wizard_steps())
    steps_->addItem(QStringLiteral("%1  %2").arg(s.number).arg(tr(s.title)));
  steps_->setMaximumHeight(kStepCount * 24 + 8);
  steps_->setMinimumHeight(kStepCount * 24 + 8);  // every step in sight, however long the page
  connect(steps_, &QListWidget::itemClicked, this, [this](QListWidgetItem* item) {
    const int step = steps_->row(item) + 1;
    if (step == controller_->state().current_step) return;
    push(commands::go_to_step(step));
  });
  layout->addWidget(steps_);
  instructions_ = new QLabel(panel);
  instructions_->setObjectName("instructions");
  instructions_->setWordWrap(true);
  instructions_->setMinimumHeight(110);
  instructions_->setAlignment(Qt::AlignTop | Qt::AlignLeft);
  instructions_->setStyleSheet(
      "QLabel{background:#f4f1e8;color:#222;padding:6px;border-radius:4px}");
  layout->addWidget(instructions_);
  pages_ = new QStackedWidget(panel);
  for (int step = kLoadStep; step <= kStepCount; ++step) {
    StepPage* page = make_step_page(step, *this).release();
    pages_->addWidget(page);
    step_pages_.push_back(page);
  }
  load_page_ = static_cast<LoadPage*>(step_pages_[0]);
  // A long page (step 7's material, zones and holes) scrolls rather than squeezing the steps.
  auto* scroll = new QScrollArea(panel);
  scroll->setObjectName("pageScroll");
  scroll->setWidgetResizable(true);
  scroll->setFrameShape(QFrame::NoFrame);
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  scroll->setWidget(pages_);
  scroll->setMinimumWidth(pages_->minimumSizeHint().width() +
                          scroll->verticalScrollBar()->sizeHint().width());
  layout->addWidget(scroll, 1);
  page_scroll_ = scroll;
  done_button_ = button(tr("Done — next step"), "done", panel);
  connect(done_button_, &QPushButton::clicked, this, [this] {
    const PlanState& s = controller_->state();
    // Step 7 with an implant the quality check refuses: said, and asked, not passed silently.
    if (s.current_step == kBuildStep && s.implant && s.implant->result().usable() &&
        !s.implant->quality().printable) {
      const QString what =
          tr("The quality check refuses this implant: %1. Step 7's page says what to try.")
              .arg(q(s.implant->quality().reasons.empty() ? std::string("see the Quality panel")
                                                          : s.implant->quality().reasons.front()));
      show_message(what, true);
      if (!interactive_ || QMessageBox::question(this, tr("Go on with a refused implant?"),
                                                 what + "\n\n" + tr("Go on to step 8 anyway?"),
                                                 QMessageBox::Yes | QMessageBox::No,
                                                 QMessageBox::No) != QMessageBox::Yes)
        return;
    }
    push(commands::complete_step(s.current_step));
  });
  layout->addWidget(done_button_);
  dock->setWidget(panel);
  dock->setMinimumWidth(360);
  addDockWidget(Qt::LeftDockWidgetArea, dock);
}

void MainWindow::build_plan_dock() {
  auto* dock = new QDockWidget(tr("Plan"), this);
  dock->setObjectName("planDock");
  dock->setFeatures(QDockWidget::NoDockWidgetFeatures);
  plan_tabs_ = new QTabWidget(dock);
  quality_ = new QTextBrowser(plan_tabs_);
  quality_->setObjectName("quality");
  plan_tabs_->addTab(quality_, tr("Quality"));
  history_ = new QListWidget(plan_tabs_);
  history_->setObjectName("history");
  connect(history_, &QListWidget::itemClicked, this, [this](QListWidgetItem* item) {
    controller_->set_index(history_->row(item));
    note_shown(tr("The plan as it was after command %1.").arg(history_->row(item)));
  });
  plan_tabs_->addTab(history_, tr("History"));

  audit_tab_ = new QWidget(plan_tabs_);
  auto* al = new QVBoxLayout(audit_tab_);
  audit_label_ = new QLabel(audit_tab_);
  audit_label_->setWordWrap(true);
  audit_slider_ = new QSlider(Qt::Horizontal, audit_tab_);
  audit_slider_->setObjectName("auditSlider");
  audit_verify_ = new QTextBrowser(audit_tab_);
  audit_verify_->setMaximumHeight(140);
  audit_table_ = new QTableWidget(audit_tab_);
  audit_table_->setColumnCount(5);
  audit_table_->setHorizontalHeaderLabels(
      {tr("time"), tr("user"), tr("step"), tr("event"), tr("what")});
  audit_table_->horizontalHeader()->setStretchLastSection(true);
  audit_table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  al->addWidget(audit_label_);
  al->addWidget(audit_slider_);
  al->addWidget(audit_verify_);
  al->addWidget(audit_table_, 1);
  connect(audit_slider_, &QSlider::valueChanged, this, [this](int i) {
    const PlanState& s = controller_->session().state_at(static_cast<size_t>(i));
    view_->show_state(s);
    const auto& stack = controller_->session().stack();
    audit_label_->setText(i == 0 ? tr("Before the first command")
                                 : tr("After command %1 of %2: %3 (%4, %5)")
                                       .arg(i)
                                       .arg(stack.size())
                                       .arg(q(describe(stack[i - 1])))
                                       .arg(q(stack[i - 1].meta.user))
                                       .arg(q(stack[i - 1].meta.ended)));
  });
  plan_tabs_->addTab(audit_tab_, tr("Audit"));
  plan_tabs_->setTabVisible(2, false);
  dock->setWidget(plan_tabs_);
  dock->setMinimumWidth(330);
  addDockWidget(Qt::RightDockWidgetArea, dock);
}

// ---------------------------------------------------------------------------------------------
// Showing the plan

void MainWindow::refresh() {
  // While a file is loading on trial, the plan open before stays on screen (it stays open if
  // the file turns out bad); the status bar shows the load's progress.
  if (controller_->on_trial()) return;
  const PlanState& s = controller_->state();
  if (!controller_->read_only()) view_->show_state(controller_->shown_state());
  if (layout_ != Layout::ThreeD)
    slices_->show_state(controller_->shown_state());
  else
    slices_->load_ct(s);  // the soft tissue is checked on it whether the slices show or not
  // A new proposal: turn to the defect it found.
  if (s.proposal_message != last_proposal_) {
    last_proposal_ = s.proposal_message;
    if (!s.markers.empty()) view_->look_at_markers();
  }
  refresh_steps();
  update_mould();
  refresh_history();
  refresh_quality();
  for (StepPage* page : step_pages_) page->show_state(s);
  const Session& session = controller_->session();
  undo_->setText(session.can_undo() ? q(session.undo_text()) : tr("Undo"));
  redo_->setText(session.can_redo() ? q(session.redo_text()) : tr("Redo"));
  undo_->setEnabled(session.can_undo() && !controller_->read_only());
  redo_->setEnabled(session.can_redo() && !controller_->read_only());
  QString title = tr("Cranioplan");
  if (!session.header().info.case_id.empty()) title += " — " + q(session.header().info.case_id);
  if (!session.is_clean() && session.index() > 0) title += " *";
  if (controller_->read_only()) title += tr(" (audit, read-only)");
  setWindowTitle(title);
  case_label_->setText(tr("Case: %1")
                           .arg(session.header().info.case_id.empty()
                                    ? tr("none")
                                    : q(session.header().info.case_id)));
  // What was just done: the window's own words (undo, redo, save), else the last command's.
  if (!s.message.empty()) show_message(q(s.message), false);
  clip_->setEnabled(s.clip_plane.has_value());
  finish_training_if_done();
  update_timers();
}

void MainWindow::refresh_steps() {
  const PlanState& s = controller_->state();
  for (int step = kLoadStep; step <= kStepCount; ++step) {
    QListWidgetItem* item = steps_->item(step - 1);
    std::string missing, why;
    const bool done = step_complete(s, step, &missing);
    const bool unlocked = step_unlocked(s, step, &why);
    // An implant the quality check refuses is built, but the step is not done well: marked
    // ✘, its page says what is wrong and what to try.
    const bool refused = step == kBuildStep && done && refused_implant();
    QString text = QStringLiteral("%1 %2  %3")
                       .arg(refused ? QStringLiteral("✘")
                            : done  ? QStringLiteral("✔")
                                    : QStringLiteral("  "))
                       .arg(step)
                       .arg(tr(wizard_steps()[step - 1].title));
    QString tip = refused ? tr("Built, but the quality check refuses the implant: see the step's "
                               "page for what to try")
                  : done  ? tr("Done")
                          : q(missing);
    if (s.stale.count(step)) {
      text += QStringLiteral("  ⚠");
      tip += "\n" + tr("Recomputed: ") + q(s.stale.at(step));
    }
    if (!unlocked) tip = q(why);
    item->setText(text);
    item->setToolTip(tip);
    Qt::ItemFlags flags = Qt::ItemIsSelectable;
    if (unlocked && !controller_->read_only()) flags |= Qt::ItemIsEnabled;
    item->setFlags(flags);
    QFont f = item->font();
    f.setBold(step == s.current_step);
    item->setFont(f);
  }
  steps_->setCurrentRow(s.current_step - 1);
  if (shown_step_ != s.current_step) {
    // Another step: its page opens at its top, and the view is set as the step needs it.
    page_scroll_->verticalScrollBar()->setValue(0);
    clip_->setChecked(s.current_step == kClipStep);
  }
  shown_step_ = s.current_step;
  pages_->setCurrentIndex(s.current_step - 1);
  StepPage* page = step_pages_[static_cast<size_t>(s.current_step - 1)];
  instructions_->setText(page->instructions_html(s));
  done_button_->setEnabled(!controller_->read_only());
  done_button_->setText(s.current_step == kExportStep ? tr("Done") : tr("Done — next step"));
  step_label_->setText(tr("Step %1 of %2: %3")
                           .arg(s.current_step)
                           .arg(kStepCount)
                           .arg(tr(wizard_steps()[s.current_step - 1].title)));
  if (timed_step_ != s.current_step) {
    timed_step_ = s.current_step;
    step_timer_.restart();
  }

  // What clicks and drags on the view do is the current page's.
  const bool editable = !controller_->read_only();
  view_->set_pick_target(editable ? page->pick_target() : SkullView::PickTarget::None);
  view_->set_markers_editable(editable && page->markers_editable());
  view_->set_handles(editable ? page->handles(s) : std::vector<SkullView::Handle>{});
}

void MainWindow::refresh_history() {
  const Session& session = controller_->session();
  history_->clear();
  history_->addItem(tr("0. (start)"));
  for (size_t i = 0; i < session.stack().size(); ++i) {
    auto* item = new QListWidgetItem(
        QStringLiteral("%1. %2").arg(i + 1).arg(q(describe(session.stack()[i]))), history_);
    if (i >= session.index()) item->setForeground(QColor(150, 150, 150));
  }
  history_->setCurrentRow(static_cast<int>(session.index()));
}

void MainWindow::refresh_quality() {
  const PlanState& s = controller_->state();
  view_->set_rim_gap(std::nullopt);  // of the implant before, if any
  if (!s.implant) {
    quality_->setHtml(tr("<p>No implant yet.</p>"));
    for (StepPage* page : step_pages_)
      page->show_verdict(tr("<p>Build the implant first (step 7).</p>"));
    return;
  }
  // The report (overlap on a fine grid, thickness, self-intersections) takes a few tenths of a
  // second on a real skull: while markers are dragged it is computed once the implant has
  // stopped changing, not for every rebuild.
  quality_->setHtml(tr("<p>Checking the implant…</p>"));
  for (StepPage* page : step_pages_) page->show_verdict(tr("<p>Checking the implant…</p>"));
  quality_timer_->start();
}

// What the quality panel shows of an implant, computed off the GUI thread.
struct MainWindow::QualityView {
  std::shared_ptr<const ImplantData> implant;  ///< the implant it is of
  QString html;
  QString verdict;  ///< for the pages: printable, or what is wrong and what to try
  std::vector<Eigen::Vector3d> intrusion;  ///< the implant's voxels in soft tissue (CT plans)
  std::optional<SoftTissueCheck> tissue;   ///< without the voxels (CT plans)
  std::shared_ptr<const ThicknessMap> thickness;  ///< the implant's, and the skull's gap to it
};

void MainWindow::show_quality() {
  const PlanState& s = controller_->state();
  // Marker edits still computed: the report waits for the implant they leave (the last one's
  // finish refreshes it), rather than take the core from them.
  if (!s.implant || controller_->editing()) return;
  // The report (a few tenths of a second on a real skull) and, with the plan's CT at hand, the
  // soft tissue under the implant are computed on a worker thread: the window stays live.
  const std::shared_ptr<const ImplantData> implant = s.implant;
  const std::shared_ptr<const Volume> ct = s.skull ? slices_->ct() : nullptr;
  const Eigen::Vector3d inside =
      s.defect_center ? *s.defect_center : (s.skull ? s.skull->centroid : Eigen::Vector3d::Zero());
  drop_watcher(quality_watcher_, this);  // an earlier report, of no use now
  quality_watcher_ = new QFutureWatcher<std::shared_ptr<QualityView>>(this);
  connect(quality_watcher_, &QFutureWatcherBase::finished, this, [this] {
    const std::shared_ptr<QualityView> v = quality_watcher_->result();
    if (v->implant != controller_->state().implant) return;  // the plan moved on
    slices_->set_highlight(v->intrusion);
    view_->set_thickness_map(&v->implant->result().mesh, v->thickness);
    view_->set_rim_gap(rim_gap_to_mark(v->implant->quality()));
    quality_->setHtml(v->html);
    judged_implant_ = v->implant;
    judged_printable_ = v->implant->quality().printable;
    judged_tissue_ = v->tissue;
    for (StepPage* page : step_pages_) page->show_verdict(v->verdict);
    refresh_steps();  // step 7's mark: printable or refused
  });
  const std::shared_ptr<const SkullInput> skull = s.skull;
  const ImplantParams params = s.implant_params ? *s.implant_params : ImplantParams{};
  quality_watcher_->setFuture(QtConcurrent::run([implant, ct, inside, skull, params] {
    auto v = std::make_shared<QualityView>();
    v->implant = implant;
    v->thickness = std::make_shared<const ThicknessMap>(
        thickness_map(implant->result().mesh, skull ? &skull->surface->mesh : nullptr));
    SoftTissueCheck tissue;
    if (ct) tissue = check_soft_tissue(implant->result().mesh, *ct, inside);
    v->intrusion = std::move(tissue.intrusion);
    if (tissue.checked) v->tissue = tissue;
    v->html = quality_html(implant->quality(), tissue.checked ? &tissue : nullptr);
    v->verdict =
        q(quality_verdict_html(implant->quality(), params, tissue.checked ? &tissue : nullptr));
    return v;
  }));
}

void MainWindow::set_thickness_map_shown(bool shown) { show_thickness_->setChecked(shown); }

bool MainWindow::refused_implant() const {
  return judged_implant_ && judged_implant_ == controller_->state().implant && !judged_printable_;
}

void MainWindow::show_mould(bool shown) {
  mould_wanted_ = shown;
  update_mould();
}

void MainWindow::update_mould() {
  const PlanState& s = controller_->state();
  if (!mould_wanted_ || !s.implant || s.current_step != kExportStep) {
    if (mould_of_) view_->set_mould(nullptr);
    for (StepPage* page : step_pages_) page->show_mould_message(QString());
    mould_of_ = nullptr;
    drop_watcher(mould_watcher_, this);
    mould_watcher_ = nullptr;
    return;
  }
  if (mould_of_ == s.implant.get()) return;  // shown, or being made
  // The mould the 3MF export would hold (seconds on a real implant), made on a worker thread.
  mould_of_ = s.implant.get();
  view_->set_mould(nullptr);
  drop_watcher(mould_watcher_, this);
  mould_watcher_ = new QFutureWatcher<std::shared_ptr<const SkullView::PreparedMould>>(this);
  const std::shared_ptr<const ImplantData> implant = s.implant;
  const std::shared_ptr<const SkullInput> skull = s.skull;
  connect(mould_watcher_, &QFutureWatcherBase::finished, this, [this, implant] {
    const std::shared_ptr<const SkullView::PreparedMould> prepared = mould_watcher_->result();
    if (implant.get() != mould_of_) return;  // the plan moved on
    const MouldResult& m = SkullView::result_of(*prepared);
    view_->set_mould(prepared);
    const QString text =
        (m.usable() ? tr("Casting mould, shown opened apart: %1.") : tr("No casting mould: %1."))
            .arg(q(m.message));
    for (StepPage* page : step_pages_) page->show_mould_message(text);
    show_message(text, !m.usable());
  });
  for (StepPage* page : step_pages_) page->show_mould_message(tr("Making the casting mould…"));
  // The mould and VTK's meshes of its halves, both off the GUI thread.
  mould_watcher_->setFuture(QtConcurrent::run([implant, skull] {
    return SkullView::prepare_mould(std::make_shared<const MouldResult>(
        mould_of(implant->result().mesh, skull ? &skull->surface->mesh : nullptr, MouldParams{})));
  }));
}

void MainWindow::wait_mould() {
  if (mould_watcher_) mould_watcher_->waitForFinished();
  QCoreApplication::processEvents();
}

void MainWindow::wait_quality() {
  if (quality_timer_->isActive()) {
    quality_timer_->stop();
    show_quality();
  }
  while (quality_watcher_ && quality_watcher_->isRunning())
    QApplication::processEvents(QEventLoop::AllEvents, 20);
  QApplication::processEvents();
}

void MainWindow::update_timers() {
  const auto fmt = [](qint64 ms) {
    const qint64 s = ms / 1000;
    return QStringLiteral("%1:%2").arg(s / 60).arg(s % 60, 2, 10, QChar('0'));
  };
  timer_label_->setText(tr("Step %1   Total %2%3")
                            .arg(fmt(step_timer_.elapsed()))
                            .arg(fmt(total_timer_.elapsed()))
                            .arg(training_reference_.isEmpty() ? QString() : tr("   (training)")));
}

void MainWindow::note_shown(const QString& text) {
  show_message(text, false);
  statusBar()->setStyleSheet("QStatusBar{background:#e3f2e1}");  // a sign that it happened
  QTimer::singleShot(1500, this, [this] { statusBar()->setStyleSheet(QString()); });
}

void MainWindow::show_message(const QString& text, bool problem) {
  statusBar()->showMessage((problem ? QStringLiteral("⚠ ") : QString()) + text,
                           problem ? 15000 : 8000);
}

// ---------------------------------------------------------------------------------------------
// Actions

void MainWindow::push(Command command, const QString& what) {
  controller_->submit(std::move(command), what);
}

void MainWindow::set_marker_type(MarkerType type) {
  marker_type_ = type;
  if (auto* b = findChild<QPushButton*>(QStringLiteral("markerType%1").arg(static_cast<int>(type))))
    b->setChecked(true);
  show_message(tr("Clicks place %1 markers.").arg(q(to_string(type)).replace('_', ' ')), false);
  refresh_steps();
}

void MainWindow::on_surface_clicked(const Eigen::Vector3d& p) {
  step_pages_[static_cast<size_t>(controller_->state().current_step - 1)]->surface_clicked(p);
}

void MainWindow::on_marker_dragged(int id, const Eigen::Vector3d& p) {
  push(commands::move_marker(id, p));
}

std::shared_ptr<const PlanState> MainWindow::preview(const Command& command) {
  return controller_->preview(command);
}

void MainWindow::open_input(const QString& path, double threshold) {
  if (!confirm_discard()) return;
  ExtractBoneSurfaceParams import;
  const bool volume = is_volume_path(path.toStdString());
  if (!volume) import.mesh_unit_mm = load_page_->mesh_unit_mm();
  if (volume && QFileInfo(path).isDir() && !choose_dicom_series(path, import)) return;
  // A CT's bone threshold: the one asked (command line, sample), else step 1's field
  // (automatic by default: 300 HU for a CT, 0.5 for a mask).
  if (volume) import.threshold = std::isfinite(threshold) ? threshold : load_page_->threshold();
  const QString case_id = QFileInfo(path).completeBaseName();
  QDir().mkpath(autosave_folder());
  const QString autosave = autosave_folder() + "/" + case_id + "-" +
                           QDateTime::currentDateTimeUtc().toString("yyyyMMdd-HHmmss") +
                           ".json.autosave";
  // On trial: the plan open now stays until the file has loaded (a bad file closes nothing).
  trial_input_ = path;
  controller_->try_new_session(SessionInfo{case_id.toStdString(), "", ""}, autosave);
  push(commands::load_skull(path.toStdString(), import), tr("Loading %1").arg(case_id));
}

void MainWindow::trial_settled(bool loaded) {
  if (loaded) {
    forget_discarded();
    add_recent(trial_input_);
    session_path_.clear();
    total_timer_.restart();
    step_timer_.restart();
  } else {
    keep_discarded();
    show_message(tr("%1 was not opened; the plan that was open is kept as it was.")
                     .arg(QFileInfo(trial_input_).fileName()),
                 true);
  }
  trial_input_.clear();
}

void MainWindow::forget_discarded() {
  if (!discarded_autosave_.isEmpty()) QFile::remove(discarded_autosave_);
  discarded_autosave_.clear();
}

void MainWindow::keep_discarded() { discarded_autosave_.clear(); }

bool MainWindow::choose_dicom_series(const QString& folder, ExtractBoneSurfaceParams& import) {
  std::vector<DicomSeries> series;
  try {
    series = list_dicom_series(folder.toStdString());
  } catch (const Error& e) {
    show_message(QString::fromStdString(e.what()), true);
    return false;
  }
  if (series.size() < 2 || !interactive_) return true;  // the reader takes the largest CT
  // The default is the reader's own choice: the largest CT series.
  QStringList items;
  int preferred = 0;
  long long best = -1;
  for (size_t i = 0; i < series.size(); ++i) {
    const DicomSeries& d = series[i];
    items << tr("%1 — %2 %3×%4×%5 — %6")
                 .arg(d.description.empty() ? tr("(no description)") : q(d.description))
                 .arg(q(d.modality))
                 .arg(d.columns)
                 .arg(d.rows)
                 .arg(d.slices)
                 .arg(q(d.uid));
    const long long size = (d.modality == "CT" ? 1LL << 40 : 0) + d.slices * d.rows * d.columns;
    if (size > best) {
      best = size;
      preferred = static_cast<int>(i);
    }
  }
  bool ok = false;
  const QString chosen = QInputDialog::getItem(
      this, tr("DICOM series"),
      tr("The folder holds %1 series. Which is the skull's CT?").arg(series.size()), items,
      preferred, false, &ok);
  if (!ok) return false;
  import.dicom_series = series[static_cast<size_t>(items.indexOf(chosen))].uid;
  return true;
}

bool MainWindow::set_mesh_unit(const std::string& name) { return load_page_->set_mesh_unit(name); }

void MainWindow::open_sample() {
  const QString path = q(sample_case_path());
  if (!QFileInfo::exists(path)) {
    show_message(tr("The sample case is not installed (%1): run scripts/install-deps.").arg(path),
                 true);
    return;
  }
  open_input(path, 300.0);
}

bool MainWindow::open_session(const QString& path) {
  if (!confirm_discard()) return false;
  try {
    // Without interaction (tests, --quit) nothing beside the plan is read or written.
    OpenOptions options;
    options.attach_autosave = interactive_;
    const RecoveryInfo info = Session::recovery_info(path.toStdString());
    if (info.available && interactive_)
      options.recover_autosave =
          QMessageBox::question(this, tr("Recover unsaved changes?"),
                                tr("%1.\n\nRecover them?").arg(q(info.message))) ==
          QMessageBox::Yes;
    // Opening replays the plan's commands (seconds for a fitted implant): on a worker thread,
    // the steps, view and panels held while it runs, the status bar counting the commands.
    struct Opened {
      std::shared_ptr<Session> session;
      std::string error;
    };
    auto done = std::make_shared<std::atomic<size_t>>(0);
    auto total = std::make_shared<std::atomic<size_t>>(0);
    options.progress = [done, total](size_t k, size_t n) {
      total->store(n);
      done->store(k);
    };
    QApplication::setOverrideCursor(Qt::WaitCursor);
    const QString name = QFileInfo(path).fileName();
    show_message(tr("Opening %1…").arg(name), false);
    const std::vector<QWidget*> held = {centralWidget(), steps_->parentWidget(), plan_tabs_,
                                        menuBar()};
    for (QWidget* w : held) w->setEnabled(false);
    progress_->setRange(0, 0);
    progress_->setVisible(true);
    QFuture<Opened> opening = QtConcurrent::run([file = path.toStdString(), options] {
      Opened o;
      try {
        o.session = std::make_shared<Session>(Session::open(file, options));
      } catch (const Error& e) {
        o.error = e.what();
      } catch (const std::exception& e) {
        o.error = file + ": unexpected error: " + e.what();
      }
      return o;
    });
    size_t shown = 0;
    while (!opening.isFinished()) {
      QApplication::processEvents(QEventLoop::AllEvents, 20);
      if (total->load() > 0 && done->load() != shown) {
        shown = done->load();
        progress_->setRange(0, static_cast<int>(total->load()));
        progress_->setValue(static_cast<int>(shown));
        show_message(tr("Opening %1: replaying command %2 of %3…")
                         .arg(name)
                         .arg(shown + 1)
                         .arg(total->load()),
                     false);
      }
    }
    for (QWidget* w : held) w->setEnabled(true);
    progress_->setRange(0, 0);
    progress_->setVisible(false);
    QApplication::restoreOverrideCursor();
    Opened opened = opening.result();
    if (!opened.session) {
      keep_discarded();
      emit controller_->failed(QString::fromStdString(opened.error));
      return false;
    }
    forget_discarded();
    controller_->set_read_only(false);
    controller_->set_session(std::move(*opened.session));
    session_path_ = path;
    plan_tabs_->setTabVisible(2, false);
    add_recent(path);
    return true;
  } catch (const Error& e) {
    QApplication::restoreOverrideCursor();
    keep_discarded();
    emit controller_->failed(QString::fromUtf8(e.what()));
    return false;
  }
}

void MainWindow::replay_to_step(int step) {
  const auto& stack = controller_->session().stack();
  size_t k = 0;
  while (k < controller_->session().index() && stack[k].meta.step <= step) ++k;
  controller_->set_index(k);
  if (controller_->state().current_step != step && step_unlocked(controller_->state(), step))
    controller_->push(commands::go_to_step(step));
}

bool MainWindow::save_session_to(const QString& path) {
  const std::string old_autosave = controller_->session().autosave_path();
  controller_->save(path);
  if (!controller_->session().is_clean()) return false;
  session_path_ = path;
  // The plan's autosave now lives beside it; the one of the unsaved plan is no longer needed.
  if (!old_autosave.empty() && q(old_autosave).startsWith(autosave_folder()))
    QFile::remove(q(old_autosave));
  add_recent(path);
  remember_dir(path);
  refresh();
  note_shown(tr("Saved the plan to %1 (%2 commands).")
                 .arg(path)
                 .arg(controller_->session().stack().size()));
  return true;
}

bool MainWindow::export_to(const QString& path, bool with_mould) {
  const PlanState& s = controller_->state();
  if (!s.implant) {
    show_message(tr("There is no implant to export: build it first (step 7)."), true);
    return false;
  }
  const QualityReport& r = s.implant->quality();
  if (interactive_) {
    // What is exported, and what the check and the CT say of it, before it is written.
    const SoftTissueCheck* tissue =
        judged_tissue_ && judged_implant_ == s.implant ? &*judged_tissue_ : nullptr;
    QMessageBox box(this);
    box.setWindowTitle(tr("Export the implant"));
    box.setTextFormat(Qt::RichText);
    box.setText(
        tr("<p><b>Export the implant to %1?</b></p>")
            .arg(QFileInfo(path).fileName().toHtmlEscaped()) +
        q(quality_verdict_html(r, s.implant_params ? *s.implant_params : ImplantParams{}, tissue)));
    box.setIcon(r.printable && !(tissue && tissue->finding) ? QMessageBox::Question
                                                            : QMessageBox::Warning);
    QString more;
    if (!r.printable) more += tr("The implant fails a check (above). ");
    if (!s.approval) more += tr("It is not approved yet (step 9: Approve the implant…).");
    box.setInformativeText(more);
    box.setStandardButtons(QMessageBox::Ok | QMessageBox::Cancel);
    box.button(QMessageBox::Ok)->setText(tr("Export"));
    if (box.exec() != QMessageBox::Ok) return false;
  } else if (!r.printable) {
    show_message(tr("Exported although a check fails: %1")
                     .arg(q(r.reasons.empty() ? std::string() : r.reasons.front())),
                 true);
  }
  remember_dir(path);
  return controller_->push(commands::export_implant(
      path.toStdString(), "",
      with_mould ? std::optional<MouldParams>(MouldParams{}) : std::nullopt));
}

void MainWindow::open_audit(const QString& path) {
  if (!confirm_discard()) return;
  try {
    QApplication::setOverrideCursor(Qt::WaitCursor);
    const VerifyReport verify = verify_session(path.toStdString());
    const SessionDocument doc = read_session_document(path.toStdString());
    Session s = Session::open(path.toStdString());
    QApplication::restoreOverrideCursor();
    forget_discarded();
    controller_->set_session(std::move(s));
    controller_->set_read_only(true);
    session_path_.clear();
    QString v = verify.ok() ? tr("<p style='color:#070'><b>This plan verifies.</b></p><ul>")
                            : tr("<p style='color:#b00'><b>This plan does NOT verify.</b></p><ul>");
    for (const auto& c : verify.checks)
      v +=
          QStringLiteral("<li>%1: %2 — %3</li>")
              .arg(q(c.name), c.ok ? tr("holds") : tr("<b>fails</b>"), q(c.detail).toHtmlEscaped());
    audit_verify_->setHtml(v + "</ul>");
    const auto rows = audit_rows(doc);
    audit_table_->setRowCount(static_cast<int>(rows.size()));
    for (size_t i = 0; i < rows.size(); ++i) {
      const auto& r = rows[i];
      const QStringList cells = {q(r.time), q(r.user), QString::number(r.step), q(r.event),
                                 q(r.what) + (r.undone ? tr(" (undone)") : QString())};
      for (int c = 0; c < cells.size(); ++c)
        audit_table_->setItem(static_cast<int>(i), c, new QTableWidgetItem(cells[c]));
    }
    audit_table_->resizeColumnsToContents();
    audit_slider_->setRange(0, static_cast<int>(controller_->session().stack().size()));
    plan_tabs_->setTabVisible(2, true);
    plan_tabs_->setCurrentIndex(2);
    audit_slider_->setValue(static_cast<int>(controller_->session().index()));
    view_->show_state(controller_->state());
    refresh();
  } catch (const Error& e) {
    QApplication::restoreOverrideCursor();
    emit controller_->failed(QString::fromUtf8(e.what()));
  }
}

void MainWindow::start_training(const QString& reference) {
  try {
    read_session_document(reference.toStdString());
  } catch (const Error& e) {
    show_message(QString::fromUtf8(e.what()), true);
    return;
  }
  training_reference_ = reference;
  training_html_.clear();
  total_timer_.restart();
  step_timer_.restart();
  show_message(tr("Training against %1: the timers run; finish the plan (export) for the "
                  "report.")
                   .arg(QFileInfo(reference).fileName()),
               false);
}

void MainWindow::finish_training_if_done() {
  if (training_reference_.isEmpty() || !training_html_.isEmpty()) return;
  if (!step_complete(controller_->state(), kExportStep)) return;
  try {
    const Session reference = Session::open(training_reference_.toStdString());
    training_html_ =
        q(cranioplan::training_report_html(training_report(controller_->session(), reference)));
    show_message(tr("Training finished: Training → Show the training report."), false);
    if (interactive_) QTimer::singleShot(0, this, [this] { show_training_report(); });
  } catch (const Error& e) {
    show_message(QString::fromUtf8(e.what()), true);
  }
}

QString MainWindow::default_plan_name() const {
  // The name the desktop knows as a plan (docs/INSTALL.md): CASE.cranioplan.json, in the
  // plan's folder.
  const std::string& id = controller_->session().header().info.case_id;
  return suggested_path((id.empty() ? tr("plan") : q(id)) + QStringLiteral(".cranioplan.json"));
}

QString MainWindow::suggested_path(const QString& file_name) const {
  // Beside the plan's file; else where the user last saved or exported; else the folder the
  // program was started in (never the skull's folder: the sample's is a system folder).
  QString dir = session_path_.isEmpty() ? QSettings().value("lastDir").toString()
                                        : QFileInfo(session_path_).absolutePath();
  if (dir.isEmpty() || !QFileInfo(dir).isDir()) dir = QDir::currentPath();
  return dir + "/" + file_name;
}

void MainWindow::remember_dir(const QString& written) {
  QSettings().setValue("lastDir", QFileInfo(written).absolutePath());
}

QString MainWindow::autosave_folder() const {
  return QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave";
}

void MainWindow::offer_recovery(std::optional<RecoveryChoice> answer) {
  QDir dir(autosave_folder());
  const QFileInfoList found =
      dir.entryInfoList({"*.autosave"}, QDir::Files, QDir::Time);  // newest first
  if (found.isEmpty()) return;
  const QFileInfo& newest = found.front();
  // Without interaction and without an answer given, it is recovered.
  RecoveryChoice choice = answer.value_or(RecoveryChoice::Recover);
  if (interactive_ && !answer) {
    // Recover it, discard it for good, or leave it for later (offered again at the next start).
    QMessageBox box(QMessageBox::Question, tr("Recover a plan?"),
                    tr("Cranioplan stopped before the plan \"%1\" was saved (last change %2).")
                        .arg(newest.completeBaseName(), newest.lastModified().toString()),
                    QMessageBox::NoButton, this);
    QPushButton* recover = box.addButton(tr("Recover"), QMessageBox::AcceptRole);
    QPushButton* discard = box.addButton(tr("Discard it"), QMessageBox::DestructiveRole);
    box.addButton(tr("Later"), QMessageBox::RejectRole);
    box.setDefaultButton(recover);
    box.exec();
    choice = box.clickedButton() == recover   ? RecoveryChoice::Recover
             : box.clickedButton() == discard ? RecoveryChoice::Discard
                                              : RecoveryChoice::Later;
  }
  if (choice == RecoveryChoice::Discard) {
    QFile::remove(newest.filePath());
    show_message(tr("Discarded the unsaved plan \"%1\".").arg(newest.completeBaseName()), false);
    return;
  }
  if (choice == RecoveryChoice::Later) return;
  try {
    controller_->set_session(Session::recover(newest.filePath().toStdString()));
    show_message(
        tr("Recovered %1 commands of the unsaved plan.").arg(controller_->session().index()),
        false);
  } catch (const Error& e) {
    show_message(QString::fromUtf8(e.what()), true);
  }
}

bool MainWindow::confirm_discard() {
  const Session& s = controller_->session();
  if (controller_->read_only() || s.index() == 0 || s.is_clean() || !interactive_) return true;
  const auto answer = QMessageBox::question(
      this, tr("Unsaved changes"), tr("The plan has unsaved changes. Save it first?"),
      QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel);
  if (answer == QMessageBox::Cancel) return false;
  if (answer == QMessageBox::Save) {
    QString path = session_path_;
    if (path.isEmpty())
      path = QFileDialog::getSaveFileName(this, tr("Save the plan"), default_plan_name(),
                                          tr("Cranioplan plan (*.cranioplan.json *.json)"));
    return !path.isEmpty() && save_session_to(path);
  }
  // Discarded on purpose: the unsaved plan's autosave is not a crash to recover from. It is
  // removed once the plan that replaces it is open (a bad file leaves the old plan, and its
  // autosave, as they were).
  const QString autosave = q(s.autosave_path());
  if (autosave.startsWith(autosave_folder())) discarded_autosave_ = autosave;
  return true;
}

void MainWindow::add_recent(const QString& path) {
  QSettings settings;
  QStringList recent = settings.value("recent").toStringList();
  recent.removeAll(path);
  recent.prepend(path);
  while (recent.size() > 8) recent.removeLast();
  settings.setValue("recent", recent);
  refresh_recent_menu();
}

void MainWindow::refresh_recent_menu() {
  recent_menu_->clear();
  for (const QString& path : QSettings().value("recent").toStringList())
    recent_menu_->addAction(path, this, [this, path] {
      if (path.endsWith(".json"))
        open_session(path);
      else
        open_input(path);
    });
  recent_menu_->setEnabled(!recent_menu_->isEmpty());
}

QImage MainWindow::screenshot() {
  wait_quality();  // a picture shows the report, not "Checking…"
  view_->update();
  QApplication::processEvents();
  return grab().toImage();
}

void MainWindow::closeEvent(QCloseEvent* event) {
  // Marker edits are the user's work: they are finished, a long computation is cancelled.
  if (controller_->editing()) controller_->wait();
  if (controller_->busy()) controller_->cancel();
  if (!confirm_discard()) {
    event->ignore();
    return;
  }
  controller_->wait();
  forget_discarded();
  event->accept();
}

}  // namespace cranioplan::gui
