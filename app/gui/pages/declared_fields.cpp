#include "declared_fields.h"

#include <QDoubleSpinBox>
#include <QSlider>
#include <QSpinBox>
#include <cmath>
#include <memory>

#include "cranioplan/model/param_spec.h"

namespace cranioplan::gui {

QString declared_tooltip(const ParamSpec& s) {
  QString text = QString::fromUtf8(s.help);
  if (!text.isEmpty()) text[0] = text[0].toUpper();
  return text;
}

QDoubleSpinBox* declared_spin(QWidget* parent, const char* name, const ParamSpec& s, double value,
                              double step) {
  auto* b = new QDoubleSpinBox(parent);
  b->setObjectName(name);
  b->setRange(s.min, s.max);
  b->setSingleStep(step);
  if (*s.unit) b->setSuffix(QStringLiteral(" ") + QString::fromUtf8(s.unit));
  b->setToolTip(declared_tooltip(s));
  b->setValue(value);
  return b;
}

void allow_unset(QDoubleSpinBox* box, const QString& text) {
  const double least = box->minimum();
  box->setMinimum(0.0);
  box->setSpecialValueText(text);
  box->setValue(0.0);
  auto previous = std::make_shared<double>(0.0);
  QObject::connect(box, &QDoubleSpinBox::valueChanged, box, [box, least, previous](double v) {
    if (v > 0.0 && v < least) {
      box->setValue(v > *previous ? least : 0.0);
      return;
    }
    *previous = v;
  });
}

QSpinBox* declared_count(QWidget* parent, const char* name, const ParamSpec& s, int value) {
  auto* b = new QSpinBox(parent);
  b->setObjectName(name);
  b->setRange(static_cast<int>(s.min), static_cast<int>(s.max));
  b->setToolTip(declared_tooltip(s));
  b->setValue(value);
  return b;
}

QSlider* declared_slider(QWidget* parent, const char* name, const ParamSpec& s, int value) {
  auto* b = new QSlider(Qt::Horizontal, parent);
  b->setObjectName(name);
  b->setRange(static_cast<int>(std::ceil(s.min)), static_cast<int>(std::floor(s.max)));
  b->setToolTip(declared_tooltip(s));
  b->setValue(value);
  return b;
}

}  // namespace cranioplan::gui
