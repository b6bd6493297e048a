#include <QFileDialog>
#include <QPushButton>
#include <QTextBrowser>
#include <QVBoxLayout>

#include "step_pages.h"

namespace cranioplan::gui {

ExportPage::ExportPage(PageHost& host) : StepPage(9, host) {
  report_ = new QTextBrowser(this);
  report_->setObjectName("exportReport");
  layout_->addWidget(report_, 1);
  for (const char* ext : {"stl", "ply"}) {
    QPushButton* b = make_button(tr("Export %1…").arg(QString(ext).toUpper()),
                                 ext[0] == 's' ? "exportStl" : "exportPly");
    connect(b, &QPushButton::clicked, this, [this, ext] {
      const QString path = QFileDialog::getSaveFileName(
          this, tr("Export the implant"), QStringLiteral("implant.%1").arg(ext),
          QStringLiteral("%1 (*.%2)").arg(QString(ext).toUpper(), ext));
      if (!path.isEmpty()) host_.export_to(path);
    });
    layout_->addWidget(b);
  }
}

void ExportPage::show_quality(const QString& html) { report_->setHtml(html); }

}  // namespace cranioplan::gui
