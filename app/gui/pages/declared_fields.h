#pragma once
// The wizard's fields for declared parameters (param_spec.h): each field's range, unit and
// tooltip come from its parameter's declaration, as the CLI's options and the session's checks
// do.
#include <QString>

class QDoubleSpinBox;
class QSlider;
class QSpinBox;
class QWidget;

namespace cranioplan {
struct ParamSpec;
}

namespace cranioplan::gui {

/// A declared parameter's help, as a sentence for a tooltip.
QString declared_tooltip(const ParamSpec& s);
/// A field for a declared length or number, named `name`, set to `value`.
QDoubleSpinBox* declared_spin(QWidget* parent, const char* name, const ParamSpec& s, double value,
                              double step);
/// A field for a declared count.
QSpinBox* declared_count(QWidget* parent, const char* name, const ParamSpec& s, int value);
/// Lets `box` (a declared_spin) be left unset: below its least value it takes 0, which reads
/// `text`; a value between 0 and the least steps to the least going up, to 0 going down.
void allow_unset(QDoubleSpinBox* box, const QString& text);
/// A slider over a declared parameter's range in whole units.
QSlider* declared_slider(QWidget* parent, const char* name, const ParamSpec& s, int value);

}  // namespace cranioplan::gui
