#include "step_page.h"

#include <QFormLayout>
#include <QLabel>
#include <QPushButton>
#include <QTextDocument>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

#include "step_pages.h"

namespace cranioplan::gui {

StepPage::StepPage(int step, PageHost& host, QWidget* parent)
    : QWidget(parent),
      host_(host),
      layout_(new QVBoxLayout(this)),
      form_(new QFormLayout),
      step_(step) {
  layout_->addLayout(form_);
}

QString StepPage::keys_hint() const {
  return tr("Keys: Ctrl+Z undo, Ctrl+Shift+Z redo, F5–F9 standard views, M mirror on/off.");
}

QString StepPage::marker_keys_hint() {
  return tr(
      "Keys: 0–3 marker type, Del delete, drag a marker to move it, Ctrl+Z undo, Ctrl+Shift+Z "
      "redo.");
}

SkullView::PickTarget StepPage::marker_pick_target(MarkerType type) {
  return is_edge(type) ? SkullView::PickTarget::Original : SkullView::PickTarget::Mirrored;
}

QString StepPage::instructions_html(const PlanState& state) const {
  const WizardStep& w = wizard_steps()[static_cast<size_t>(step_ - 1)];
  std::string missing;
  const bool done = step_complete(state, step_, &missing);
  return QStringLiteral("<b>%1. %2</b><br>%3<br><br>%4<br><i>%5</i>")
      .arg(w.number)
      .arg(tr(w.title))
      .arg(tr(w.instructions).toHtmlEscaped())
      .arg(done ? tr("<span style='color:#070'>Done.</span>")
                : tr("<span style='color:#a50'>To do: %1</span>")
                      .arg(QString::fromStdString(missing).toHtmlEscaped()))
      .arg(keys_hint());
}

QPushButton* StepPage::make_button(const QString& text, const char* name) {
  auto* b = new QPushButton(text, this);
  b->setObjectName(name);
  return b;
}

QPushButton* StepPage::add_button(const QString& text, const char* name) {
  QPushButton* b = make_button(text, name);
  form_->addRow(b);
  return b;
}

void StepPage::set_wrapped_text(QLabel* label, const QString& text) {
  label->setText(text);
  if (std::find(wrapped_.begin(), wrapped_.end(), label) == wrapped_.end())
    wrapped_.push_back(label);
  fit_wrapped();
}

void StepPage::fit_wrapped() {
  // A page lies in a stacked widget, which does not pass the height a wrapped label needs for
  // its width on to the layout: each such label (a full row of the form) asks for it itself,
  // at the width the page gives a row.
  const QMargins outer = layout_->contentsMargins(), inner = form_->contentsMargins();
  const int row = width() - outer.left() - outer.right() - inner.left() - inner.right();
  for (QLabel* label : wrapped_) {
    // The rich text laid out as the label lays it out (QLabel's own heightForWidth leaves out
    // the lists' margins).
    QTextDocument text;
    text.setDefaultFont(label->font());
    text.setHtml(label->text());
    text.setTextWidth(std::max(row, 150));
    label->setMinimumHeight(
        label->text().isEmpty() ? 0 : static_cast<int>(std::ceil(text.size().height())) + 4);
  }
}

void StepPage::resizeEvent(QResizeEvent* event) {
  QWidget::resizeEvent(event);
  fit_wrapped();
}

std::unique_ptr<StepPage> make_step_page(int step, PageHost& host) {
  std::unique_ptr<StepPage> page;
  switch (step) {
    case 1:
      page = std::make_unique<LoadPage>(host);
      break;
    case 2:
      page = std::make_unique<PlanePage>(host);
      break;
    case 3:
      page = std::make_unique<MirrorPage>(host);
      break;
    case 4:
      page = std::make_unique<ClipPage>(host);
      break;
    case 5:
      page = std::make_unique<EdgeMarkersPage>(host);
      break;
    case 6:
      page = std::make_unique<SurfaceMarkersPage>(host);
      break;
    case 7:
      page = std::make_unique<BuildPage>(host);
      break;
    case 8:
      page = std::make_unique<SmoothPage>(host);
      break;
    case 9:
      page = std::make_unique<ExportPage>(host);
      break;
    default:
      return nullptr;
  }
  // The controls at the top, the space left below them.
  static_cast<QVBoxLayout*>(page->layout())->addStretch(1);
  return page;
}

}  // namespace cranioplan::gui
