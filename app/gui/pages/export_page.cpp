#include <QCheckBox>
#include <QFileDialog>
#include <QInputDialog>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QVBoxLayout>
#include <utility>

#include "step_pages.h"

namespace cranioplan::gui {

ExportPage::ExportPage(PageHost& host) : StepPage(kExportStep, host) {
  verdict_ = new QLabel(this);
  verdict_->setObjectName("exportVerdict");
  verdict_->setWordWrap(true);
  verdict_->setTextFormat(Qt::RichText);
  layout_->addWidget(verdict_);
  // STL and PLY for any printer's software; 3MF (millimetres, the plan's hash inside) for
  // those that take it.
  const std::pair<const char*, const char*> formats[] = {
      {"stl", "exportStl"}, {"ply", "exportPly"}, {"3mf", "export3mf"}};
  for (const auto& [ext, name] : formats) {
    QPushButton* b = make_button(tr("Export %1…").arg(QString(ext).toUpper()), name);
    connect(b, &QPushButton::clicked, this, [this, ext = ext] {
      const QString path = QFileDialog::getSaveFileName(
          this, tr("Export the implant"),
          host_.suggested_path(QStringLiteral("implant.%1").arg(ext)),
          QStringLiteral("%1 (*.%2)").arg(QString(ext).toUpper(), ext));
      if (!path.isEmpty()) host_.export_to(path, QString(ext) == "3mf" && mould_->isChecked());
    });
    layout_->addWidget(b);
  }
  mould_ = new QCheckBox(tr("3MF with a casting mould (PMMA in theatre)"), this);
  mould_->setObjectName("exportMould");
  mould_->setToolTip(
      tr("Two printable halves around the implant, with alignment keys, a pour channel and a "
         "vent, in the 3MF beside the implant; shown opened apart in the view"));
  connect(mould_, &QCheckBox::toggled, this, [this](bool on) { host_.show_mould(on); });
  layout_->addWidget(mould_);
  mould_info_ = new QLabel(this);
  mould_info_->setObjectName("mouldInfo");
  mould_info_->setWordWrap(true);
  mould_info_->hide();
  layout_->addWidget(mould_info_);
  // Sign-off: the surgeon approves the implant as it stands; any later change withdraws it.
  QPushButton* approve = make_button(tr("Approve the implant…"), "approve");
  approve->setToolTip(tr("Records who approved, when, and the implant's SHA-256"));
  connect(approve, &QPushButton::clicked, this, [this] {
    bool ok = false;
    const QString by =
        QInputDialog::getText(this, tr("Approve the implant"), tr("Approved by (name):"),
                              QLineEdit::Normal, QString(), &ok);
    if (!ok || by.trimmed().isEmpty()) return;
    const QString role = QInputDialog::getText(this, tr("Approve the implant"), tr("Role:"),
                                               QLineEdit::Normal, tr("neurosurgeon"), &ok);
    if (!ok) return;
    host_.push(commands::approve(by.trimmed().toStdString(), role.trimmed().toStdString()),
               tr("Approving the implant"));
  });
  layout_->addWidget(approve);
  approval_ = new QLabel(this);
  approval_->setObjectName("approval");
  approval_->setWordWrap(true);
  layout_->addWidget(approval_);
}

void ExportPage::show_verdict(const QString& html) { set_wrapped_text(verdict_, html); }

void ExportPage::show_mould_message(const QString& text) {
  mould_info_->setText(text);
  mould_info_->setVisible(!text.isEmpty());
}

void ExportPage::show_state(const PlanState& s) {
  if (s.approval)
    approval_->setText(tr("<span style='color:#060'><b>Approved</b> by %1 (%2); implant SHA-256 "
                          "%3…</span>")
                           .arg(QString::fromStdString(s.approval->by).toHtmlEscaped(),
                                QString::fromStdString(s.approval->role).toHtmlEscaped(),
                                QString::fromStdString(s.approval->implant_sha256.substr(0, 12))));
  else if (!s.approval_withdrawn.empty())
    approval_->setText(tr("<span style='color:#a00'><b>Approval withdrawn:</b> %1.</span>")
                           .arg(QString::fromStdString(s.approval_withdrawn).toHtmlEscaped()));
  else
    approval_->setText(tr("Not approved yet."));
}

}  // namespace cranioplan::gui
