#include "main_window.h"

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QDateTime>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDir>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFileInfo>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
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
#include <QSettings>
#include <QShortcut>
#include <QSlider>
#include <QSpinBox>
#include <QStackedWidget>
#include <QStandardPaths>
#include <QStatusBar>
#include <QTabWidget>
#include <QTableWidget>
#include <QTextBrowser>
#include <QTimer>
#include <QVBoxLayout>
#include <cmath>
#include <filesystem>

#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/io/read_volume.h"
#include "cranioplan/model/error.h"
#include "cranioplan/sessions/audit.h"
#include "cranioplan/sessions/marker_files.h"
#include "cranioplan/sessions/sha256.h"

namespace cranioplan::gui {

namespace {

QString q(const std::string& s) { return QString::fromStdString(s); }

QPushButton* button(const QString& text, const char* name, QWidget* parent = nullptr) {
  auto* b = new QPushButton(text, parent);
  b->setObjectName(name);
  return b;
}

QString quality_html(const QualityReport& r) { return q(quality_report_html(r)); }

// The landmark names of the step-2 list, in order.
const char* kLandmarkNames[] = {"nasion", "orbit_left", "orbit_right", "midline"};

}  // namespace

MainWindow::MainWindow(QWidget* parent)
    : QMainWindow(parent), controller_(new PlanController(this)), view_(new SkullView(this)) {
  setWindowTitle(tr("Cranioplan"));
  resize(1500, 950);
  setCentralWidget(view_);
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
    pages_->setEnabled(!busy);
  });
  connect(view_, &SkullView::surfaceClicked, this, &MainWindow::on_surface_clicked);
  connect(view_, &SkullView::markerDragged, this, &MainWindow::on_marker_dragged);
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
    const QString path = QFileDialog::getOpenFileName(
        this, tr("Open a skull"), QString(),
        tr("Skull (*.stl *.ply *.obj *.off *.vtp *.inv3 *.nrrd *.nhdr *.nii *.nii.gz);;All (*)"));
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
    const QString path = QFileDialog::getOpenFileName(this, tr("Open a plan"), QString(),
                                                      tr("Cranioplan session (*.json)"));
    if (!path.isEmpty()) open_session(path);
  });
  open_plan->setShortcut(QKeySequence::Open);
  open_plan->setObjectName("openSession");
  QAction* save = file->addAction(tr("Save session"), this, [this] {
    QString path = session_path_;
    if (path.isEmpty())
      path = QFileDialog::getSaveFileName(this, tr("Save the plan"), QString(),
                                          tr("Cranioplan session (*.json)"));
    if (!path.isEmpty()) save_session_to(path);
  });
  save->setShortcut(QKeySequence::Save);
  save->setObjectName("saveSession");
  file->addAction(tr("Save session as…"), this, [this] {
    const QString path = QFileDialog::getSaveFileName(this, tr("Save the plan"), QString(),
                                                      tr("Cranioplan session (*.json)"));
    if (!path.isEmpty()) save_session_to(path);
  });
  recent_menu_ = file->addMenu(tr("Recent files"));
  refresh_recent_menu();
  file->addSeparator();
  QAction* audit = file->addAction(tr("Audit a session (read-only)…"), this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("Audit a plan"), QString(),
                                                      tr("Cranioplan session (*.json)"));
    if (!path.isEmpty()) open_audit(path);
  });
  audit->setObjectName("audit");
  file->addSeparator();
  file->addAction(tr("Quit"), this, &QWidget::close)->setShortcut(QKeySequence::Quit);

  build_edit_view_menus();
  build_training_help_menus();
}

// Edit (undo, redo, delete, notes) and View (standard views, the mirror and the plane).
void MainWindow::build_edit_view_menus() {
  QMenu* edit = menuBar()->addMenu(tr("&Edit"));
  undo_ = edit->addAction(tr("Undo"), controller_, &PlanController::undo);
  undo_->setShortcut(QKeySequence(Qt::CTRL | Qt::Key_Z));
  undo_->setObjectName("undo");
  redo_ = edit->addAction(tr("Redo"), controller_, &PlanController::redo);
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
  QAction* show_plane = view->addAction(tr("Show midsagittal plane"));
  show_plane->setCheckable(true);
  show_plane->setChecked(true);
  connect(show_plane, &QAction::toggled, view_, &SkullView::set_plane_visible);
}

// Training (a reference plan and the report) and Help (About).
void MainWindow::build_training_help_menus() {
  QMenu* training = menuBar()->addMenu(tr("&Training"));
  training->addAction(tr("Start training with a reference plan…"), this, [this] {
    const QString path = QFileDialog::getOpenFileName(this, tr("The expert's plan"), QString(),
                                                      tr("Cranioplan session (*.json)"));
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
  steps_->setMaximumHeight(9 * 24 + 8);
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
  for (int step = 1; step <= 9; ++step) pages_->addWidget(make_page(step));
  layout->addWidget(pages_, 1);
  done_button_ = button(tr("Done — next step"), "done", panel);
  connect(done_button_, &QPushButton::clicked, this,
          [this] { push(commands::complete_step(controller_->state().current_step)); });
  layout->addWidget(done_button_);
  dock->setWidget(panel);
  dock->setMinimumWidth(360);
  addDockWidget(Qt::LeftDockWidgetArea, dock);
}

QWidget* MainWindow::make_page(int step) {
  auto* page = new QWidget;
  auto* layout = new QVBoxLayout(page);
  auto* form = new QFormLayout;
  layout->addLayout(form);
  const PageParts parts{page, layout, form};
  switch (step) {
    case 1:
      fill_load_page(parts);
      break;
    case 2:
      fill_plane_page(parts);
      break;
    case 3:
      fill_mirror_page(parts);
      break;
    case 4:
      fill_clip_page(parts);
      break;
    case 5:
    case 6:
      fill_markers_page(parts, step);
      break;
    case 7:
      fill_build_page(parts);
      break;
    case 8:
      fill_smooth_page(parts);
      break;
    case 9:
      fill_export_page(parts);
      break;
    default:
      break;
  }
  layout->addStretch(1);
  return page;
}

// Step 1, load skull.
void MainWindow::fill_load_page(const PageParts& p) {
  auto* open = button(tr("Open mesh or CT…"), "pageOpen", p.page);
  connect(open, &QPushButton::clicked, this, [this] {
    const QString path = QFileDialog::getOpenFileName(
        this, tr("Open a skull"), QString(),
        tr("Skull (*.stl *.ply *.obj *.off *.vtp *.inv3 *.nrrd *.nhdr *.nii *.nii.gz);;All "
           "(*)"));
    if (!path.isEmpty()) open_input(path);
  });
  auto* sample = button(tr("Open the sample case"), "pageSample", p.page);
  connect(sample, &QPushButton::clicked, this, [this] { open_sample(); });
  threshold_ = new QDoubleSpinBox(p.page);
  threshold_->setObjectName("threshold");
  threshold_->setRange(-1000, 3000);
  threshold_->setValue(300);
  threshold_->setSuffix(" HU");
  threshold_->setToolTip(tr("Bone threshold for CTs (masks use 0.5)"));
  units_ = new QComboBox(p.page);
  units_->setObjectName("meshUnits");
  for (const LengthUnit& u : length_units())
    units_->addItem(QStringLiteral("%1 (%2)").arg(tr(u.label), QString::fromLatin1(u.name)), u.mm);
  units_->setToolTip(
      tr("The length unit a mesh file was written in (STL, PLY, OBJ and OFF carry none). A "
         "skull of the wrong size is refused, naming the unit it looks to be in."));
  p.form->addRow(open);
  p.form->addRow(sample);
  p.form->addRow(tr("Mesh units"), units_);
  p.form->addRow(tr("CT bone threshold"), threshold_);
  skull_info_ = new QLabel(p.page);
  skull_info_->setWordWrap(true);
  p.form->addRow(skull_info_);
}

// Step 2, landmarks and the midsagittal plane.
void MainWindow::fill_plane_page(const PageParts& p) {
  landmark_ = new QComboBox(p.page);
  landmark_->setObjectName("landmark");
  landmark_->addItems(
      {tr("Nasion"), tr("Left orbit centre"), tr("Right orbit centre"), tr("Midline point")});
  p.form->addRow(tr("Click places"), landmark_);
  auto* clear = button(tr("Clear landmarks"), "clearLandmarks", p.page);
  connect(clear, &QPushButton::clicked, this, [this] {
    for (const char* name : kLandmarkNames) push(commands::clear_landmark(name));
  });
  p.form->addRow(clear);
  auto* fit = button(tr("Fit plane"), "fitPlane", p.page);
  fit->setToolTip(tr("Landmarks (if all three are set) or automatic, refined by symmetry"));
  connect(fit, &QPushButton::clicked, this,
          [this] { push(commands::fit_plane(), tr("Fitting the plane")); });
  p.form->addRow(fit);
  plane_info_ = new QLabel(p.page);
  plane_info_->setWordWrap(true);
  p.form->addRow(plane_info_);
  auto* box = new QGroupBox(tr("Adjust by hand"), p.page);
  auto* bl = new QFormLayout(box);
  adjust_axis_ = new QComboBox(box);
  adjust_axis_->addItems({tr("Up–down axis"), tr("Front–back axis")});
  adjust_angle_ = new QDoubleSpinBox(box);
  adjust_angle_->setRange(-20, 20);
  adjust_angle_->setSingleStep(0.5);
  adjust_angle_->setSuffix("°");
  adjust_shift_ = new QDoubleSpinBox(box);
  adjust_shift_->setRange(-20, 20);
  adjust_shift_->setSingleStep(0.5);
  adjust_shift_->setSuffix(" mm");
  auto* apply = button(tr("Apply"), "adjustPlane", box);
  connect(apply, &QPushButton::clicked, this, [this] {
    const Eigen::Vector3d axis =
        adjust_axis_->currentIndex() == 0 ? Eigen::Vector3d::UnitZ() : Eigen::Vector3d::UnitY();
    push(commands::adjust_plane(axis, adjust_angle_->value(), adjust_shift_->value()),
         tr("Moving the plane"));
  });
  // Sliders beside the fields, in half-degree and half-millimetre steps.
  auto linked_slider = [box](QDoubleSpinBox* field) {
    auto* slider = new QSlider(Qt::Horizontal, box);
    slider->setRange(-40, 40);
    QObject::connect(slider, &QSlider::valueChanged, field,
                     [field](int v) { field->setValue(0.5 * v); });
    QObject::connect(field, &QDoubleSpinBox::valueChanged, slider, [slider](double v) {
      const QSignalBlocker block(slider);
      slider->setValue(static_cast<int>(std::lround(2.0 * v)));
    });
    return slider;
  };
  bl->addRow(tr("Turn about"), adjust_axis_);
  bl->addRow(tr("Angle"), adjust_angle_);
  bl->addRow(QString(), linked_slider(adjust_angle_));
  bl->addRow(tr("Shift"), adjust_shift_);
  bl->addRow(QString(), linked_slider(adjust_shift_));
  bl->addRow(apply);
  p.layout->addWidget(box);
}

// Step 3, mirror and register.
void MainWindow::fill_mirror_page(const PageParts& p) {
  auto* mirror = button(tr("Mirror skull"), "mirror", p.page);
  connect(mirror, &QPushButton::clicked, this,
          [this] { push(commands::mirror(), tr("Mirroring")); });
  p.form->addRow(mirror);
  roi_only_ = new QCheckBox(tr("Only around a point (click the skull)"), p.page);
  roi_only_->setObjectName("roiOnly");
  roi_radius_ = new QDoubleSpinBox(p.page);
  roi_radius_->setRange(20, 200);
  roi_radius_->setValue(70);
  roi_radius_->setSuffix(" mm");
  auto* reg = button(tr("Register"), "register", p.page);
  connect(reg, &QPushButton::clicked, this, [this] {
    RegisterParams p;
    if (roi_only_->isChecked() && roi_center_) {
      RegionOfInterest roi;
      roi.center = *roi_center_;
      roi.radius = roi_radius_->value();
      p.roi = roi;
    }
    push(commands::register_mirror(p), tr("Registering"));
  });
  p.form->addRow(roi_only_);
  p.form->addRow(tr("Region radius"), roi_radius_);
  p.form->addRow(reg);
  register_info_ = new QLabel(p.page);
  register_info_->setWordWrap(true);
  p.form->addRow(register_info_);
  auto* box = new QGroupBox(tr("Nudge the mirror"), p.page);
  auto* grid = new QHBoxLayout(box);
  const std::pair<QString, Eigen::Vector3d> moves[] = {{"←", {-1, 0, 0}},     {"→", {1, 0, 0}},
                                                       {"front", {0, -1, 0}}, {"back", {0, 1, 0}},
                                                       {"↑", {0, 0, 1}},      {"↓", {0, 0, -1}}};
  for (const auto& [label, delta] : moves) {
    auto* b = new QPushButton(label, box);
    b->setToolTip(tr("Move the mirrored skull 1 mm"));
    connect(b, &QPushButton::clicked, this, [this, delta = delta] {
      push(commands::move_mirrored(Eigen::Vector3d::UnitZ(), 0.0, Eigen::Vector3d::Zero(), delta),
           tr("Moving the mirror"));
    });
    grid->addWidget(b);
  }
  p.layout->addWidget(box);
  auto* opacity = new QSlider(Qt::Horizontal, p.page);
  opacity->setRange(5, 100);
  opacity->setValue(45);
  connect(opacity, &QSlider::valueChanged, this,
          [this](int v) { view_->set_mirror_opacity(v / 100.0); });
  p.form->addRow(tr("Mirror opacity"), opacity);
}

// Step 4, clip and inspect.
void MainWindow::fill_clip_page(const PageParts& p) {
  clip_on_ = new QCheckBox(tr("Clip the skulls"), p.page);
  clip_on_->setObjectName("clipOn");
  clip_axis_ = new QComboBox(p.page);
  clip_axis_->addItems({tr("Left–right"), tr("Front–back"), tr("Up–down")});
  clip_position_ = new QSlider(Qt::Horizontal, p.page);
  clip_position_->setObjectName("clipPosition");
  clip_position_->setRange(-120, 120);
  auto send = [this] { push(clip_command()); };
  connect(clip_on_, &QCheckBox::toggled, this, send);
  connect(clip_axis_, &QComboBox::currentIndexChanged, this, [this, send] {
    if (clip_on_->isChecked()) send();
  });
  connect(clip_position_, &QSlider::sliderReleased, this, send);
  connect(clip_position_, &QSlider::valueChanged, this, [this, send] {
    if (!clip_position_->isSliderDown() && clip_on_->isChecked()) send();
  });
  p.form->addRow(clip_on_);
  p.form->addRow(tr("Cut across"), clip_axis_);
  p.form->addRow(tr("Position"), clip_position_);
}

// Steps 5 and 6, edge and surface markers.
void MainWindow::fill_markers_page(const PageParts& p, int step) {
  const bool edges = step == 5;
  for (int t : edges ? std::vector<int>{0, 1} : std::vector<int>{2, 3}) {
    const auto type = static_cast<MarkerType>(t);
    auto* b = new QPushButton(
        QStringLiteral("[%1] %2").arg(t).arg(q(to_string(type)).replace('_', ' ')), p.page);
    b->setObjectName(QStringLiteral("markerType%1").arg(t));
    b->setCheckable(true);
    b->setAutoExclusive(true);
    connect(b, &QPushButton::clicked, this, [this, type] { set_marker_type(type); });
    p.form->addRow(b);
  }
  if (edges) {
    auto* propose = button(tr("Propose markers automatically"), "propose", p.page);
    connect(propose, &QPushButton::clicked, this, [this] {
      // With several openings in the skull, the one where the user has put edge markers is
      // meant (otherwise the largest).
      ProposeParams params;
      params.detect.near = edge_marker_centre(controller_->state().markers);
      push(commands::propose_markers(params), tr("Finding the defect and proposing markers"));
    });
    auto* import = button(tr("Import markers…"), "importMarkers", p.page);
    connect(import, &QPushButton::clicked, this, [this] {
      const QString path = QFileDialog::getOpenFileName(this, tr("Markers"), QString(),
                                                        tr("Markers (*.json *.csv)"));
      if (path.isEmpty()) return;
      try {
        push(commands::import_markers(read_markers_file(path.toStdString()), path.toStdString(),
                                      sha256_file(path.toStdString())));
      } catch (const Error& e) {
        show_message(QString::fromUtf8(e.what()), true);
      }
    });
    auto* clear = button(tr("Clear markers"), "clearMarkers", p.page);
    connect(clear, &QPushButton::clicked, this, [this] { push(commands::clear_markers()); });
    p.form->addRow(propose);
    p.form->addRow(import);
    p.form->addRow(clear);
  }
  marker_counts_[edges ? 0 : 1] = new QLabel(p.page);
  p.form->addRow(marker_counts_[edges ? 0 : 1]);
  if (edges) {
    // What the last proposal found stays in view while the markers are edited: where the
    // rim was not seen, the outline between edge markers far apart needs a look.
    proposal_note_ = new QLabel(p.page);
    proposal_note_->setObjectName("proposalNote");
    proposal_note_->setWordWrap(true);
    p.form->addRow(proposal_note_);
  }
}

// Step 7, build the implant.
void MainWindow::fill_build_page(const PageParts& p) {
  implant_method_ = new QComboBox(p.page);
  implant_method_->setObjectName("implantMethod");
  implant_method_->addItems({tr("Shell (fitted surfaces)"), tr("Delaunay 3D (the paper's)")});
  implant_resolution_ = new QDoubleSpinBox(p.page);
  implant_resolution_->setRange(0.3, 5);
  implant_resolution_->setValue(1.0);
  implant_resolution_->setSingleStep(0.1);
  implant_resolution_->setSuffix(" mm");
  implant_thickness_ = new QDoubleSpinBox(p.page);
  implant_thickness_->setRange(0, 15);
  implant_thickness_->setValue(0);
  implant_thickness_->setSpecialValueText(tr("measured at the rim"));
  implant_thickness_->setSuffix(" mm");
  implant_fit_ = new QDoubleSpinBox(p.page);
  implant_fit_->setObjectName("implantFit");
  implant_fit_->setRange(0, 8);
  implant_fit_->setSingleStep(0.5);
  implant_fit_->setSpecialValueText(tr("off"));
  implant_fit_->setSuffix(" mm");
  implant_fit_->setToolTip(
      tr("Build the shell this far over the bone and subtract the skull: the implant meets "
         "the cut face all around and never enters the bone (about 1 s per rebuild)"));
  auto* build = button(tr("Build implant"), "build", p.page);
  connect(build, &QPushButton::clicked, this, [this] {
    ImplantParams p;
    p.method =
        implant_method_->currentIndex() == 0 ? ImplantMethod::Shell : ImplantMethod::Delaunay3D;
    p.resolution_mm = implant_resolution_->value();
    if (implant_thickness_->value() > 0) p.thickness_mm = implant_thickness_->value();
    p.surface_smoothing = 0.003;
    p.fit_to_bone_mm = implant_fit_->value();
    push(commands::build_implant(p), tr("Building the implant"));
  });
  p.form->addRow(tr("Method"), implant_method_);
  p.form->addRow(tr("Resolution"), implant_resolution_);
  p.form->addRow(tr("Thickness without inner markers"), implant_thickness_);
  p.form->addRow(tr("Fit to the bone"), implant_fit_);
  p.form->addRow(build);
  implant_info_ = new QLabel(p.page);
  implant_info_->setWordWrap(true);
  p.form->addRow(implant_info_);
}

// Step 8, smooth and refine.
void MainWindow::fill_smooth_page(const PageParts& p) {
  smooth_radius_ = new QSlider(Qt::Horizontal, p.page);
  smooth_radius_->setObjectName("smoothRadius");
  smooth_radius_->setRange(2, 40);
  smooth_radius_->setValue(10);
  smooth_weight_ = new QSlider(Qt::Horizontal, p.page);
  smooth_weight_->setObjectName("smoothWeight");
  smooth_weight_->setRange(1, 10);
  smooth_weight_->setValue(2);
  smooth_iterations_ = new QSpinBox(p.page);
  smooth_iterations_->setRange(1, 20);
  smooth_project_ = new QCheckBox(tr("Put smoothed markers back on the mirror"), p.page);
  smooth_project_->setChecked(true);
  smooth_info_ = new QLabel(p.page);
  smooth_info_->setWordWrap(true);
  for (QSlider* s : {smooth_radius_, smooth_weight_})
    connect(s, &QSlider::valueChanged, this, &MainWindow::preview_smoothing);
  connect(smooth_iterations_, &QSpinBox::valueChanged, this, &MainWindow::preview_smoothing);
  auto* apply = button(tr("Apply smoothing"), "applySmoothing", p.page);
  connect(apply, &QPushButton::clicked, this, [this] {
    push(commands::smooth_markers(
             {static_cast<double>(smooth_radius_->value()),
              static_cast<double>(smooth_weight_->value()), smooth_iterations_->value()},
             smooth_project_->isChecked()),
         tr("Smoothing"));
  });
  p.form->addRow(tr("Radius"), smooth_radius_);
  p.form->addRow(tr("Edge-marker weight"), smooth_weight_);
  p.form->addRow(tr("Iterations"), smooth_iterations_);
  p.form->addRow(smooth_project_);
  p.form->addRow(apply);
  p.form->addRow(smooth_info_);
}

// Step 9, check and export.
void MainWindow::fill_export_page(const PageParts& p) {
  export_report_ = new QTextBrowser(p.page);
  export_report_->setObjectName("exportReport");
  p.layout->addWidget(export_report_, 1);
  for (const char* ext : {"stl", "ply"}) {
    auto* b = button(tr("Export %1…").arg(QString(ext).toUpper()),
                     ext[0] == 's' ? "exportStl" : "exportPly", p.page);
    connect(b, &QPushButton::clicked, this, [this, ext] {
      const QString path = QFileDialog::getSaveFileName(
          this, tr("Export the implant"), QStringLiteral("implant.%1").arg(ext),
          QStringLiteral("%1 (*.%2)").arg(QString(ext).toUpper(), ext));
      if (!path.isEmpty()) export_to(path);
    });
    p.layout->addWidget(b);
  }
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
  connect(history_, &QListWidget::itemClicked, this,
          [this](QListWidgetItem* item) { controller_->set_index(history_->row(item)); });
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
  const PlanState& s = controller_->state();
  if (!controller_->read_only()) view_->show_state(s);
  // A new proposal: turn to the defect it found.
  if (s.proposal_message != last_proposal_) {
    last_proposal_ = s.proposal_message;
    if (!s.markers.empty()) view_->look_at_markers();
  }
  refresh_steps();
  refresh_history();
  refresh_quality();
  refresh_page();
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
  if (!s.message.empty()) show_message(q(s.message), false);
  finish_training_if_done();
  update_timers();
}

void MainWindow::refresh_steps() {
  const PlanState& s = controller_->state();
  for (int step = 1; step <= 9; ++step) {
    QListWidgetItem* item = steps_->item(step - 1);
    std::string missing, why;
    const bool done = step_complete(s, step, &missing);
    const bool unlocked = step_unlocked(s, step, &why);
    QString text = QStringLiteral("%1 %2  %3")
                       .arg(done ? QStringLiteral("✔") : QStringLiteral("  "))
                       .arg(step)
                       .arg(tr(wizard_steps()[step - 1].title));
    QString tip = done ? tr("Done") : q(missing);
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
  shown_step_ = s.current_step;
  pages_->setCurrentIndex(s.current_step - 1);
  const WizardStep& w = wizard_steps()[s.current_step - 1];
  std::string missing;
  const bool done = step_complete(s, s.current_step, &missing);
  QString keys;
  if (s.current_step == 5 || s.current_step == 6 || s.current_step == 8)
    keys =
        tr("<br><i>Keys: 0–3 marker type, Del delete, drag a marker to move it, Ctrl+Z "
           "undo, Ctrl+Shift+Z redo.</i>");
  else
    keys =
        tr("<br><i>Keys: Ctrl+Z undo, Ctrl+Shift+Z redo, F5–F9 standard views, M mirror "
           "on/off.</i>");
  instructions_->setText(QStringLiteral("<b>%1. %2</b><br>%3<br><br>%4%5")
                             .arg(w.number)
                             .arg(tr(w.title))
                             .arg(tr(w.instructions).toHtmlEscaped())
                             .arg(done ? tr("<span style='color:#070'>Done.</span>")
                                       : tr("<span style='color:#a50'>To do: %1</span>")
                                             .arg(q(missing).toHtmlEscaped()))
                             .arg(keys));
  done_button_->setEnabled(!controller_->read_only());
  done_button_->setText(s.current_step == 9 ? tr("Done") : tr("Done — next step"));
  step_label_->setText(tr("Step %1 of 9: %2").arg(s.current_step).arg(tr(w.title)));
  if (timed_step_ != s.current_step) {
    timed_step_ = s.current_step;
    step_timer_.restart();
  }

  // Clicks: landmarks in step 2, the region centre in step 3, markers in 5, 6 and 8.
  const int st = s.current_step;
  SkullView::PickTarget target = SkullView::PickTarget::None;
  if (st == 2 || st == 3) target = SkullView::PickTarget::Original;
  if (st == 5 || st == 6 || st == 8)
    target =
        is_edge(marker_type_) ? SkullView::PickTarget::Original : SkullView::PickTarget::Mirrored;
  view_->set_pick_target(controller_->read_only() ? SkullView::PickTarget::None : target);
  view_->set_markers_editable(!controller_->read_only() && (st == 5 || st == 6 || st == 8));
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
  if (!s.implant) {
    quality_->setHtml(tr("<p>No implant yet.</p>"));
    if (export_report_) export_report_->setHtml(tr("<p>Build the implant first (step 7).</p>"));
    return;
  }
  // The report (overlap on a fine grid, thickness, self-intersections) takes a few tenths of a
  // second on a real skull: while markers are dragged it is computed once the implant has
  // stopped changing, not for every rebuild.
  quality_->setHtml(tr("<p>Checking the implant…</p>"));
  if (export_report_) export_report_->setHtml(tr("<p>Checking the implant…</p>"));
  quality_timer_->start();
}

void MainWindow::show_quality() {
  const PlanState& s = controller_->state();
  if (!s.implant) return;
  const QString html = quality_html(s.implant->quality());
  quality_->setHtml(html);
  if (export_report_) export_report_->setHtml(html);
}

void MainWindow::refresh_page() {
  const PlanState& s = controller_->state();
  if (skull_info_) {
    QString info = tr("No skull loaded.");
    if (s.skull) {
      const LoadedSkull& loaded = s.skull->surface->loaded;
      info = tr("%1<br>%2 triangles")
                 .arg(q(loaded.description).toHtmlEscaped())
                 .arg(s.skull->surface->mesh.n_faces());
      // What the reader changed or found (a skull turned outward, non-manifold edges).
      for (const std::string& w : loaded.warnings)
        info +=
            QStringLiteral("<br><span style='color:#a05a00'>⚠ %1</span>").arg(q(w).toHtmlEscaped());
    }
    skull_info_->setText(info);
  }
  if (plane_info_) {
    QString t;
    if (s.plane_fit)
      t = tr("Fit: symmetry RMS %1 mm, %2% inliers (%3 start)")
              .arg(s.plane_fit->symmetry_rms_mm, 0, 'f', 2)
              .arg(100.0 * s.plane_fit->inlier_fraction, 0, 'f', 0)
              .arg(q(s.plane_fit->initial_method));
    const int n = (s.landmarks.nasion ? 1 : 0) + (s.landmarks.orbit_left ? 1 : 0) +
                  (s.landmarks.orbit_right ? 1 : 0);
    plane_info_->setText(
        tr("Landmarks: %1 of 3 set, %2 midline points.").arg(n).arg(s.landmarks.midline.size()) +
        (t.isEmpty() ? QString() : "<br>" + t));
  }
  if (register_info_)
    register_info_->setText(
        s.registration ? (s.registration->usable()
                              ? tr("Registered: RMS %1 mm, %2 iterations")
                                    .arg(s.registration->rms_mm, 0, 'f', 2)
                                    .arg(s.registration->iterations)
                              : tr("Registration failed: %1").arg(q(s.registration->message)))
                       : (s.mirrored ? tr("Mirrored, not registered.") : tr("Not mirrored yet.")));
  int counts[4] = {0, 0, 0, 0};
  for (const auto& m : s.markers) ++counts[static_cast<int>(m.type)];
  if (marker_counts_[0])
    marker_counts_[0]->setText(tr("Outer edge: %1, inner edge: %2").arg(counts[0]).arg(counts[1]));
  if (marker_counts_[1])
    marker_counts_[1]->setText(
        tr("Outer surface: %1, inner surface: %2").arg(counts[2]).arg(counts[3]));
  if (proposal_note_) {
    QString note =
        s.proposal_message.empty() ? QString() : tr("Last proposal: %1").arg(q(s.proposal_message));
    if (!s.unseen_rim.empty())
      note +=
          tr(" The orange lines in the view run along the stretches of the rim no ray saw: "
             "the outline there goes straight from one edge marker to the next.");
    proposal_note_->setText(note);
    proposal_note_->setVisible(!s.proposal_message.empty());
  }
  // The build controls show the parameters the plan's implant was built with (an automatic
  // plan is fitted to the bone), so pressing Build again keeps them unless changed.
  if (implant_fit_ && s.implant_params) {
    const ImplantParams& p = *s.implant_params;
    const QSignalBlocker b1(implant_method_), b2(implant_resolution_), b3(implant_thickness_),
        b4(implant_fit_);
    implant_method_->setCurrentIndex(p.method == ImplantMethod::Shell ? 0 : 1);
    implant_resolution_->setValue(p.resolution_mm);
    implant_thickness_->setValue(std::isnan(p.thickness_mm) ? 0.0 : p.thickness_mm);
    implant_fit_->setValue(p.fit_to_bone_mm);
  }
  if (implant_info_)
    implant_info_->setText(
        s.implant
            ? tr("Implant: %1 triangles, %2")
                  .arg(s.implant->result().mesh.n_faces())
                  .arg(s.implant->result().watertight ? tr("watertight") : tr("not watertight"))
            : tr("No implant yet."));
  if (clip_on_) {
    const QSignalBlocker b1(clip_on_);
    clip_on_->setChecked(s.clip_plane.has_value());
  }
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

void MainWindow::show_message(const QString& text, bool problem) {
  statusBar()->showMessage((problem ? QStringLiteral("⚠ ") : QString()) + text,
                           problem ? 15000 : 8000);
}

// ---------------------------------------------------------------------------------------------
// Actions

void MainWindow::push(Command command, const QString& what) {
  if (PlanController::is_long(command))
    controller_->push_async(std::move(command), what.isEmpty() ? q(describe(command)) : what);
  else
    controller_->push(std::move(command));
}

void MainWindow::set_marker_type(MarkerType type) {
  marker_type_ = type;
  if (auto* b = findChild<QPushButton*>(QStringLiteral("markerType%1").arg(static_cast<int>(type))))
    b->setChecked(true);
  show_message(tr("Clicks place %1 markers.").arg(q(to_string(type)).replace('_', ' ')), false);
  refresh_steps();
}

void MainWindow::on_surface_clicked(const Eigen::Vector3d& p) {
  const int step = controller_->state().current_step;
  if (step == 2) {
    push(commands::set_landmark(kLandmarkNames[landmark_->currentIndex()], p));
    if (landmark_->currentIndex() < 2) landmark_->setCurrentIndex(landmark_->currentIndex() + 1);
  } else if (step == 3) {
    roi_center_ = p;
    roi_only_->setChecked(true);
    show_message(tr("Registration region centred at the clicked point."), false);
  } else if (step == 5 || step == 6 || step == 8) {
    push(commands::add_marker(marker_type_, p));
  }
}

void MainWindow::on_marker_dragged(int id, const Eigen::Vector3d& p) {
  push(commands::move_marker(id, p));
}

Command MainWindow::clip_command() const {
  if (!clip_on_->isChecked()) return commands::clear_clip_plane();
  const PlanState& s = controller_->state();
  const Eigen::Vector3d center = s.skull ? s.skull->centroid : Eigen::Vector3d::Zero();
  Eigen::Vector3d n = Eigen::Vector3d::Unit(clip_axis_->currentIndex());
  return commands::set_clip_plane(Plane::through(center + clip_position_->value() * n, n));
}

void MainWindow::preview_smoothing() {
  if (!controller_->state().implant) return;
  const Command c = commands::smooth_markers(
      {static_cast<double>(smooth_radius_->value()), static_cast<double>(smooth_weight_->value()),
       smooth_iterations_->value()},
      smooth_project_->isChecked());
  smooth_info_->setText(tr("Radius %1 mm, edge weight %2 — preview (Apply to keep it)")
                            .arg(smooth_radius_->value())
                            .arg(smooth_weight_->value()));
  if (auto preview = controller_->preview(c)) view_->show_state(*preview);
}

void MainWindow::open_input(const QString& path, double threshold) {
  if (!confirm_discard()) return;
  ExtractBoneSurfaceParams import;
  const bool volume = is_volume_path(path.toStdString());
  if (!volume) import.mesh_unit_mm = units_->currentData().toDouble();
  if (volume && QFileInfo(path).isDir() && !choose_dicom_series(path, import)) return;
  if (volume) {
    import.threshold = std::isfinite(threshold) ? threshold : threshold_->value();
    if (interactive_ && !std::isfinite(threshold)) {
      bool ok = false;
      const double v = QInputDialog::getDouble(
          this, tr("Bone threshold"),
          tr("Iso-value for the bone surface (CT: Hounsfield units, about 200–400; masks: 0.5):"),
          threshold_->value(), -1000, 3000, 1, &ok);
      if (!ok) return;
      import.threshold = v;
      threshold_->setValue(v);
    }
  }
  const QString case_id = QFileInfo(path).completeBaseName();
  QDir().mkpath(autosave_folder());
  const QString autosave = autosave_folder() + "/" + case_id + "-" +
                           QDateTime::currentDateTimeUtc().toString("yyyyMMdd-HHmmss") +
                           ".json.autosave";
  controller_->new_session(SessionInfo{case_id.toStdString(), "", ""}, autosave);
  session_path_.clear();
  total_timer_.restart();
  add_recent(path);
  push(commands::load_skull(path.toStdString(), import), tr("Loading %1").arg(case_id));
}

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

bool MainWindow::set_mesh_unit(const std::string& name) {
  const std::optional<LengthUnit> unit = length_unit_named(name);
  if (!unit) return false;
  units_->setCurrentIndex(units_->findData(unit->mm));
  return true;
}

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
    QApplication::setOverrideCursor(Qt::WaitCursor);
    Session s = Session::open(path.toStdString(), options);
    QApplication::restoreOverrideCursor();
    controller_->set_read_only(false);
    controller_->set_session(std::move(s));
    session_path_ = path;
    plan_tabs_->setTabVisible(2, false);
    add_recent(path);
    return true;
  } catch (const Error& e) {
    QApplication::restoreOverrideCursor();
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
  show_message(tr("Saved %1").arg(path), false);
  refresh();
  return true;
}

bool MainWindow::export_to(const QString& path) {
  const PlanState& s = controller_->state();
  if (!s.implant) {
    show_message(tr("There is no implant to export: build it first (step 7)."), true);
    return false;
  }
  const QualityReport& r = s.implant->quality();
  if (interactive_) {
    QMessageBox box(this);
    box.setWindowTitle(tr("Quality report before export"));
    box.setTextFormat(Qt::RichText);
    box.setText(quality_html(r));
    box.setIcon(r.printable ? QMessageBox::Information : QMessageBox::Warning);
    if (!r.printable)
      box.setInformativeText(tr("The implant fails a check (listed above). Export anyway?"));
    box.setStandardButtons(QMessageBox::Ok | QMessageBox::Cancel);
    if (box.exec() != QMessageBox::Ok) return false;
  } else if (!r.printable) {
    show_message(tr("Exported although a check fails: %1")
                     .arg(q(r.reasons.empty() ? std::string() : r.reasons.front())),
                 true);
  }
  return controller_->push(commands::export_implant(path.toStdString()));
}

void MainWindow::open_audit(const QString& path) {
  if (!confirm_discard()) return;
  try {
    QApplication::setOverrideCursor(Qt::WaitCursor);
    const VerifyReport verify = verify_session(path.toStdString());
    const SessionDocument doc = read_session_document(path.toStdString());
    Session s = Session::open(path.toStdString());
    QApplication::restoreOverrideCursor();
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
  if (!step_complete(controller_->state(), 9)) return;
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

QString MainWindow::autosave_folder() const {
  return QStandardPaths::writableLocation(QStandardPaths::AppDataLocation) + "/autosave";
}

void MainWindow::offer_recovery() {
  QDir dir(autosave_folder());
  const QFileInfoList found =
      dir.entryInfoList({"*.autosave"}, QDir::Files, QDir::Time);  // newest first
  if (found.isEmpty()) return;
  const QFileInfo& newest = found.front();
  if (interactive_ && QMessageBox::question(
                          this, tr("Recover a plan?"),
                          tr("Cranioplan stopped before the plan \"%1\" was saved (last change "
                             "%2).\n\nRecover it?")
                              .arg(newest.completeBaseName(), newest.lastModified().toString())) !=
                          QMessageBox::Yes)
    return;
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
      path = QFileDialog::getSaveFileName(this, tr("Save the plan"), QString(),
                                          tr("Cranioplan session (*.json)"));
    return !path.isEmpty() && save_session_to(path);
  }
  // Discarded on purpose: the unsaved plan's autosave is not a crash to recover from.
  const QString autosave = q(s.autosave_path());
  if (autosave.startsWith(autosave_folder())) QFile::remove(autosave);
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
  if (quality_timer_->isActive()) {  // a picture shows the report, not "Checking…"
    quality_timer_->stop();
    show_quality();
  }
  view_->update();
  QApplication::processEvents();
  return grab().toImage();
}

void MainWindow::closeEvent(QCloseEvent* event) {
  if (controller_->busy()) controller_->cancel();
  if (!confirm_discard()) {
    event->ignore();
    return;
  }
  controller_->wait();
  event->accept();
}

}  // namespace cranioplan::gui
