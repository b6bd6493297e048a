// The design report for sign-off: pictures of the plan rendered in the window's 3D view, the
// report's HTML (sessions/audit.h) beside them, and a PDF of it through Qt's PDF writer.
#include <QApplication>
#include <QFile>
#include <QFileInfo>
#include <QImage>
#include <QPageSize>
#include <QPdfWriter>
#include <QTextDocument>
#include <QUrl>

#include "cranioplan/sessions/audit.h"
#include "main_window.h"

namespace cranioplan::gui {

bool MainWindow::write_design_report(const QString& html_path) {
  if (!controller_->state().implant) {
    show_message(tr("There is no implant to report on: build it first (step 7)."), true);
    return false;
  }
  const QFileInfo info(html_path);
  const QString dir = info.absolutePath(), stem = info.completeBaseName();
  const bool thickness_was_shown = show_thickness_->isChecked();
  const bool mirror_was_shown = show_mirror_->isChecked();
  show_mirror_->setChecked(false);  // the implant on the patient's skull, nothing over it
  struct Shot {
    const char* caption;
    const char* suffix;
    std::optional<SkullView::StandardView> view;  // none: along the defect (the markers)
    bool thickness;
  };
  using V = SkullView::StandardView;
  const Shot shots[] = {{"Along the defect", "defect", std::nullopt, false},
                        {"Front", "front", V::Front, false},
                        {"Right side", "right", V::Right, false},
                        {"Top", "top", V::Top, false},
                        {"Thickness map", "thickness", std::nullopt, true}};
  std::vector<ReportImage> images;
  for (const Shot& shot : shots) {
    set_thickness_map_shown(shot.thickness);
    wait_quality();  // the thickness map is computed with the quality report
    if (shot.view)
      view_->set_standard_view(*shot.view);
    else
      view_->look_at_markers();
    view_->update();
    QApplication::processEvents();
    const QString file = stem + "_" + shot.suffix + ".png";
    if (!view_->grabFramebuffer().save(dir + "/" + file)) {
      show_message(tr("Cannot write %1.").arg(dir + "/" + file), true);
      set_thickness_map_shown(thickness_was_shown);
      show_mirror_->setChecked(mirror_was_shown);
      return false;
    }
    images.push_back({shot.caption, file.toStdString()});
  }
  set_thickness_map_shown(thickness_was_shown);
  show_mirror_->setChecked(mirror_was_shown);
  view_->look_at_markers();

  const QString html = QString::fromStdString(
      design_report_html(controller_->session(), images, CRANIOPLAN_VERSION));
  QFile out(html_path);
  if (!out.open(QIODevice::WriteOnly | QIODevice::Truncate) || out.write(html.toUtf8()) < 0) {
    show_message(tr("Cannot write %1.").arg(html_path), true);
    return false;
  }
  out.close();
  // The PDF: the same HTML laid out by Qt on A4, its pictures read from beside it.
  const QString pdf_path = dir + "/" + stem + ".pdf";
  QTextDocument document;
  for (const ReportImage& image : images) {
    const QString file = QString::fromStdString(image.file);
    document.addResource(QTextDocument::ImageResource, QUrl(file), QImage(dir + "/" + file));
  }
  document.setHtml(html);
  QPdfWriter pdf(pdf_path);
  pdf.setPageSize(QPageSize(QPageSize::A4));
  pdf.setTitle(tr("Cranioplan design report"));
  pdf.setCreator(QStringLiteral("Cranioplan " CRANIOPLAN_VERSION));
  document.print(&pdf);
  if (!QFileInfo(pdf_path).exists() || QFileInfo(pdf_path).size() == 0) {
    show_message(tr("Cannot write %1.").arg(pdf_path), true);
    return false;
  }
  show_message(tr("Design report written: %1 and %2.").arg(html_path, pdf_path), false);
  return true;
}

}  // namespace cranioplan::gui
