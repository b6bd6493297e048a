#include "pause_meter.h"

#include <QTimer>
#include <algorithm>

namespace cranioplan::gui {

namespace {
constexpr int kIntervalMs = 10;
constexpr size_t kKept = 5;
}  // namespace

PauseMeter::PauseMeter(std::function<QString()> context, QObject* parent)
    : QObject(parent), context_(std::move(context)), timer_(new QTimer(this)) {
  timer_->setTimerType(Qt::PreciseTimer);
  timer_->setInterval(kIntervalMs);
  connect(timer_, &QTimer::timeout, this, &PauseMeter::tick);
  clock_.start();
  last_ns_ = clock_.nsecsElapsed();
  timer_->start();
}

void PauseMeter::tick() {
  const qint64 now = clock_.nsecsElapsed();
  const double held = static_cast<double>(now - last_ns_) * 1e-6 - kIntervalMs;
  last_ns_ = now;
  if (held <= 0.0) return;
  if (longest_.size() == kKept && held <= longest_.back().ms) return;
  longest_.push_back({held, static_cast<double>(now) * 1e-9, context_ ? context_() : QString()});
  std::sort(longest_.begin(), longest_.end(),
            [](const Pause& a, const Pause& b) { return a.ms > b.ms; });
  if (longest_.size() > kKept) longest_.pop_back();
}

QString PauseMeter::summary() const {
  QStringList parts;
  for (const Pause& p : longest_)
    parts << QStringLiteral("%1 ms at %2 s (%3)")
                 .arg(p.ms, 0, 'f', 0)
                 .arg(p.at_s, 0, 'f', 1)
                 .arg(p.context.isEmpty() ? QStringLiteral("-") : p.context);
  return parts.join(QStringLiteral("; "));
}

}  // namespace cranioplan::gui
