// cranioplan [MESH|VOLUME|SESSION] [--sample] [--units U] [--step N] [--screenshot OUT.png]
// [--thickness-map] [--mould] [--report OUT.html] [--pauses] [--turn N] [--quit]
#include <QApplication>
#include <QCheckBox>
#include <QCommandLineParser>
#include <QFileInfo>
#include <QStatusBar>
#include <QTimer>
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "cranioplan/algorithms/geometry/huge_pages.h"
#include "main_window.h"
#include "pause_meter.h"

namespace {

using cranioplan::gui::MainWindow;

// The program's options, beside the help and version.
struct Options {
  QCommandLineOption sample{"sample", "open the sample case (Cranium.inv3)"};
  QCommandLineOption step{
      "step", "show a session as it was at step N (1-9); a skull just opened, step N", "N"};
  QCommandLineOption screenshot{"screenshot", "save a picture of the window", "OUT.png"};
  QCommandLineOption quit{"quit", "quit when done (no dialogs)"};
  QCommandLineOption view{"view", "front, back, left, right, top or markers", "VIEW"};
  QCommandLineOption units{"units", "a mesh file's length unit: mm, cm, m, in or um", "U"};
  QCommandLineOption layout{
      "layout",
      "3d, four (3D and the three CT slices in equal panes), or axial, coronal or sagittal (that "
      "slice alone)",
      "LAYOUT"};
  QCommandLineOption window_preset{"window", "CT window: bone, soft or brain", "W"};
  QCommandLineOption thickness{"thickness-map",
                               "colour the implant by its thickness (View → Thickness map)"};
  QCommandLineOption mould{"mould",
                           "in step 9, show the casting mould opened apart (3MF with a mould)"};
  QCommandLineOption report{
      "report", "write the design report (HTML, its pictures and a PDF beside it)", "OUT.html"};
  QCommandLineOption pauses{
      "pauses",
      "when quitting, print the window's longest pauses (the GUI thread held) and when the "
      "first picture of the skull was drawn"};
  QCommandLineOption turn{
      "turn",
      "turn the view once around in N frames with the camera moving (the coarse copies a drag "
      "draws) and in 3 at rest, and print each way's frame times",
      "N"};

  void add_to(QCommandLineParser& parser) const {
    parser.addOptions({sample, units, step, screenshot, quit, view, layout, window_preset,
                       thickness, mould, report, pauses, turn});
  }
};

// What the command line opens: the sample, a session (at a step), a skull or CT (up to a step),
// or nothing (then, interactively, the offer to recover an autosave). False when a session
// could not be opened.
bool open_from_command_line(MainWindow& window, const QCommandLineParser& parser, const Options& o,
                            bool automated) {
  const QStringList files = parser.positionalArguments();
  bool ok = true;
  if (parser.isSet(o.sample)) {
    window.open_sample();
  } else if (!files.isEmpty()) {
    const QString file = files.front();
    if (file.endsWith(".json", Qt::CaseInsensitive)) {
      ok = window.open_session(file);
      if (ok && parser.isSet(o.step)) window.replay_to_step(parser.value(o.step).toInt());
    } else {
      window.open_input(file);
      window.controller().wait();
      if (parser.isSet(o.step)) window.replay_to_step(parser.value(o.step).toInt());
    }
  } else if (!automated) {
    window.offer_recovery();
  }
  return ok;
}

// The view, layout, thickness map, mould and CT window the command line asks for.
void apply_look(MainWindow& window, const QCommandLineParser& parser, const Options& o) {
  if (parser.isSet(o.view)) {
    const QString v = parser.value(o.view).toLower();
    using V = cranioplan::gui::SkullView::StandardView;
    if (v == "markers")
      window.view().look_at_markers();
    else
      window.view().set_standard_view(v == "back"    ? V::Back
                                      : v == "left"  ? V::Left
                                      : v == "right" ? V::Right
                                      : v == "top"   ? V::Top
                                                     : V::Front);
  }
  if (parser.isSet(o.layout)) {
    using L = MainWindow::Layout;
    const QString l = parser.value(o.layout).toLower();
    window.set_layout(l == "four" || l == "both" ? L::FourUp
                      : l == "axial"             ? L::Axial
                      : l == "coronal"           ? L::Coronal
                      : l == "sagittal"          ? L::Sagittal
                                                 : L::ThreeD);
    window.slices().wait_loaded();
  }
  if (parser.isSet(o.thickness)) window.set_thickness_map_shown(true);
  if (parser.isSet(o.mould)) {
    if (auto* box = window.findChild<QCheckBox*>("exportMould")) box->setChecked(true);
    window.wait_mould();
  }
  if (parser.isSet(o.window_preset)) {
    using P = cranioplan::gui::SlicePanel::Preset;
    const QString w = parser.value(o.window_preset).toLower();
    window.slices().apply_preset(w == "brain" ? P::Brain : w == "soft" ? P::SoftTissue : P::Bone);
  }
}

// --turn: the view turned once around in `frames` frames moving and 3 at rest, the frame times
// printed.
void print_turn_times(MainWindow& window, int frames) {
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
  };
  auto longest = [](const std::vector<double>& v) {
    return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
  };
  window.view().wait_for_coarse_copies();  // as after a moment's pause, made on a worker
  std::vector<double> moving = window.view().time_turn(frames, true);
  const double copies = moving.empty() ? 0.0 : moving.front();
  if (!moving.empty()) moving.erase(moving.begin());
  const std::vector<double> still = window.view().time_turn(3, false);
  std::printf(
      "turning the view: moving %d frames, median %.0f ms, longest %.0f ms (coarse copies "
      "made in %.0f ms); at rest 3 frames, median %.0f ms, longest %.0f ms\n",
      frames, median(moving), longest(moving), copies, median(still), longest(still));
}

}  // namespace

int main(int argc, char** argv) {
  cranioplan::start_with_huge_pages(argv);
  cranioplan::gui::SkullView::set_default_surface_format();

  // --help and --version print and quit: no window, so no display is needed for them.
  const bool text_only = std::any_of(argv + 1, argv + argc, [](const char* a) {
    for (const char* o : {"--help", "-h", "-?", "--help-all", "--version", "-v"})
      if (std::strcmp(a, o) == 0) return true;
    return false;
  });
  std::unique_ptr<QCoreApplication> application =
      text_only ? std::make_unique<QCoreApplication>(argc, argv)
                : std::make_unique<QApplication>(argc, argv);
  QCoreApplication& app = *application;
  QCoreApplication::setOrganizationName("Cranioplan");
  QCoreApplication::setApplicationName("Cranioplan");
  QCoreApplication::setApplicationVersion(CRANIOPLAN_VERSION);

  QCommandLineParser parser;
  parser.setApplicationDescription(
      "Cranioplan: plan a patient-specific cranial implant, step by step.");
  parser.addHelpOption();
  parser.addVersionOption();
  parser.addPositionalArgument("FILE", "a skull mesh, a CT volume or a saved session (.json)");
  const Options o;
  o.add_to(parser);
  parser.process(app);

  cranioplan::gui::MainWindow window;
  if (parser.isSet(o.units) && !window.set_mesh_unit(parser.value(o.units).toStdString())) {
    std::fprintf(stderr, "cranioplan: --units: unknown length unit '%s'\n",
                 parser.value(o.units).toLocal8Bit().constData());
    return 2;
  }
  const bool automated = parser.isSet(o.quit);
  window.set_interactive(!automated);
  // Bad input is reported on stderr too (the window shows it in the status bar), and an
  // automated run that met one exits with 3, like cranioplan-cli.
  bool failed = false;
  QObject::connect(&window.controller(), &cranioplan::gui::PlanController::failed,
                   [&failed](const QString& message) {
                     failed = true;
                     std::fprintf(stderr, "cranioplan: %s\n", message.toLocal8Bit().constData());
                   });
  std::unique_ptr<cranioplan::gui::PauseMeter> meter;
  double first_picture_s = -1.0;  // when the first frame with the skull was drawn
  if (parser.isSet(o.pauses)) {
    meter = std::make_unique<cranioplan::gui::PauseMeter>(
        [&window] { return window.statusBar()->currentMessage(); });
    QObject::connect(
        &window.view(), &cranioplan::gui::SkullView::skullFirstDrawn,
        [&first_picture_s] { first_picture_s = cranioplan::gui::seconds_since_start(); });
    QObject::connect(&app, &QCoreApplication::aboutToQuit, [&meter, &first_picture_s] {
      std::printf("longest pauses of the window: %s\n", meter->summary().toLocal8Bit().constData());
      if (first_picture_s >= 0.0)
        std::printf("first picture of the skull: %.2f s after the program started\n",
                    first_picture_s);
    });
  }
  window.show();

  bool ok = open_from_command_line(window, parser, o, automated);
  window.controller().wait();
  apply_look(window, parser, o);
  if (parser.isSet(o.turn)) {
    const int frames = std::max(1, parser.value(o.turn).toInt());
    QTimer::singleShot(300, &window, [&window, frames, automated, ok, &failed] {
      print_turn_times(window, frames);
      if (automated) QApplication::exit(ok && !failed ? 0 : 3);
    });
  } else if (parser.isSet(o.report)) {
    const QString out = parser.value(o.report);
    QTimer::singleShot(300, &window, [&window, out, automated, &ok] {
      const bool written = window.write_design_report(out);
      std::fprintf(written ? stdout : stderr, "%s %s\n", written ? "wrote" : "cannot write",
                   out.toLocal8Bit().constData());
      ok = ok && written;
      if (automated) QApplication::exit(ok ? 0 : 3);
    });
  } else if (parser.isSet(o.screenshot)) {
    const QString out = parser.value(o.screenshot);
    QTimer::singleShot(300, &window, [&window, out, automated, ok, &failed] {
      const bool saved = window.screenshot().save(out);
      std::fprintf(saved ? stdout : stderr, "%s %s\n", saved ? "wrote" : "cannot write",
                   out.toLocal8Bit().constData());
      if (automated) QApplication::exit(saved && ok && !failed ? 0 : 3);
    });
  } else if (automated) {
    QTimer::singleShot(0, &app, [ok, &failed] { QApplication::exit(ok && !failed ? 0 : 3); });
  }
  return app.exec();
}
