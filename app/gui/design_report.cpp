// The design report for sign-off: pictures of the plan rendered in the window's 3D view, the
// report's HTML (sessions/audit.h) beside them, and a PDF of it through Qt's PDF writer.
#include <QApplication>
#include <QFile>
#include <QFileInfo>
#include <QFont>
#include <QImage>
#include <QPageSize>
#include <QPdfWriter>
#include <QTextDocument>
#include <QUrl>
#include <algorithm>
#include <array>
#include <optional>
#include <tuple>

#include "cranioplan/algorithms/geometry/slices.h"
#include "cranioplan/sessions/audit.h"
#include "main_window.h"

namespace cranioplan::gui {

namespace {

// The report's pictures of the 3D view: caption, file suffix, the standard view (none: along
// the defect), and whether the thickness map is shown.
struct Shot {
  const char* caption;
  const char* suffix;
  std::optional<SkullView::StandardView> view;
  bool thickness;
};
const Shot kShots[] = {
    {"Along the defect", "defect", std::nullopt, false},
    {"From the front", "front", SkullView::StandardView::Front, false},
    {"From the right", "right", SkullView::StandardView::Right, false},
    {"From above", "top", SkullView::StandardView::Top, false},
    {"Thickness of the implant and its gap to the bone (mm)", "thickness", std::nullopt, true}};

bool write_text(const QString& path, const QString& text) {
  QFile out(path);
  return out.open(QIODevice::WriteOnly | QIODevice::Truncate) && out.write(text.toUtf8()) >= 0;
}

// The PDF: the report's HTML laid out by Qt on A4, its pictures read from `dir` beside it.
// Whether it was written.
bool write_report_pdf(const QString& html, const std::vector<ReportImage>& images,
                      const QString& dir, const QString& pdf_path, const QString& title) {
  QTextDocument document;
  for (const ReportImage& image : images) {
    const QString file = QString::fromStdString(image.file);
    document.addResource(QTextDocument::ImageResource, QUrl(file), QImage(dir + "/" + file));
  }
  // 8 pt on A4: the first page holds the identity, the implant and the whole quality table.
  QFont font = document.defaultFont();
  font.setPointSizeF(8.0);
  document.setDefaultFont(font);
  document.setHtml(html);
  QPdfWriter pdf(pdf_path);
  pdf.setPageSize(QPageSize(QPageSize::A4));
  pdf.setTitle(title);
  pdf.setCreator(QStringLiteral("Cranioplan " CRANIOPLAN_VERSION));
  document.print(&pdf);
  return QFileInfo(pdf_path).exists() && QFileInfo(pdf_path).size() > 0;
}

}  // namespace

bool MainWindow::write_design_report(const QString& html_path) {
  if (!controller_->state().implant) {
    show_message(tr("There is no implant to report on: build it first (step 7)."), true);
    return false;
  }
  const QFileInfo info(html_path);
  const QString dir = info.absolutePath(), stem = info.completeBaseName();
  // The report's findings, the soft tissue's among them: the plan's CT read first (its arrival
  // checks the implant again with it).
  slices_->show_state(controller_->state());
  slices_->wait_loaded();
  wait_quality();
  // The pictures show the implant on the patient's skull and nothing over it: no mirror, no
  // plane, no markers; each framed on the implant and the bone around it.
  const bool thickness_was_shown = show_thickness_->isChecked();
  const bool mirror_was_shown = show_mirror_->isChecked();
  const Layout layout_was = layout_;
  const std::array<double, 10> camera_was = view_->camera();
  show_mirror_->setChecked(false);
  view_->set_plane_visible(false);
  view_->set_markers_visible(false);
  const auto restore = [&] {
    set_thickness_map_shown(thickness_was_shown);
    show_mirror_->setChecked(mirror_was_shown);
    view_->set_plane_visible(findChild<QAction*>("showPlane")->isChecked());
    view_->set_markers_visible(true);
    set_layout(layout_was);
    view_->set_camera(camera_was);  // the view as the user left it
  };
  std::vector<ReportImage> images;
  const auto save = [&](const QImage& grabbed, const QString& suffix, const char* caption,
                        ReportImage::Kind kind) {
    // Square pictures around the middle (where the implant is framed): two to a row on A4.
    const int side = std::min(grabbed.width(), grabbed.height());
    const QImage picture =
        grabbed.copy((grabbed.width() - side) / 2, (grabbed.height() - side) / 2, side, side);
    const QString file = stem + "_" + suffix + ".png";
    if (!picture.save(dir + "/" + file)) {
      show_message(tr("Cannot write %1.").arg(dir + "/" + file), true);
      return false;
    }
    images.push_back({caption, file.toStdString(), kind});
    return true;
  };
  set_layout(Layout::ThreeD);
  QApplication::processEvents();
  // Square pictures drawn square (the layout gives the view its size back afterwards), so that
  // the legends and letters at the view's edges are in them.
  const int side_3d = std::min(view_->width(), view_->height());
  for (const Shot& shot : kShots) {
    set_thickness_map_shown(shot.thickness);
    wait_quality();  // the thickness map is computed with the quality report
    view_->resize(side_3d, side_3d);
    view_->look_at_implant(shot.view);
    view_->update();
    QApplication::processEvents(QEventLoop::ExcludeUserInputEvents);
    if (!save(view_->grabFramebuffer(), shot.suffix, shot.caption,
              shot.thickness ? ReportImage::Kind::Thickness : ReportImage::Kind::View)) {
      restore();
      return false;
    }
  }
  // The CT through the implant's middle, each slice alone in the centre, zoomed on the implant
  // with its outline (a plan without a CT has none to show).
  slices_->show_state(controller_->state());
  slices_->wait_loaded();
  if (slices_->has_ct()) {
    const Eigen::Vector3d was = slices_->cursor();
    const Eigen::Vector3d middle = vertex_centroid(controller_->state().implant->result().mesh);
    slices_->set_cursor(middle);
    const std::tuple<SliceOrientation, Layout, const char*, const char*> cuts[] = {
        {SliceOrientation::Axial, Layout::Axial, "axial", "CT, axial, through the implant"},
        {SliceOrientation::Coronal, Layout::Coronal, "coronal", "CT, coronal, through the implant"},
        {SliceOrientation::Sagittal, Layout::Sagittal, "sagittal",
         "CT, sagittal, through the implant"}};
    for (const auto& [orientation, alone, suffix, caption] : cuts) {
      set_layout(alone);
      QApplication::processEvents();
      SliceView& v = slices_->view(orientation);
      // A square picture (the layout gives the view back its size afterwards), twice the
      // fitted size, the implant's middle in its middle; letters, position and scale within.
      const int side = std::min(v.width(), v.height());
      v.resize(side, side);
      v.fit();
      v.zoom_by(2.0, v.to_widget(middle));
      v.pan_by(QPointF(v.width() / 2.0, v.height() / 2.0) - v.to_widget(middle));
      const QImage picture = v.grab().toImage();
      v.fit();
      if (!save(picture, suffix, caption, ReportImage::Kind::Slice)) {
        slices_->set_cursor(was);
        restore();
        return false;
      }
    }
    slices_->set_cursor(was);
  }
  restore();

  const QString html = QString::fromStdString(design_report_html(
      controller_->session(), images, CRANIOPLAN_VERSION,
      judged_tissue_ && judged_implant_ == controller_->state().implant ? &*judged_tissue_
                                                                        : nullptr));
  if (!write_text(html_path, html)) {
    show_message(tr("Cannot write %1.").arg(html_path), true);
    return false;
  }
  const QString pdf_path = dir + "/" + stem + ".pdf";
  if (!write_report_pdf(html, images, dir, pdf_path, tr("Cranioplan design report"))) {
    show_message(tr("Cannot write %1.").arg(pdf_path), true);
    return false;
  }
  remember_dir(html_path);
  note_shown(tr("Design report written: %1 and %2.").arg(html_path, pdf_path));
  return true;
}

}  // namespace cranioplan::gui
