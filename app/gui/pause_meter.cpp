#include "pause_meter.h"

#include <unistd.h>

#include <QTimer>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

namespace cranioplan::gui {

double seconds_since_start() {
  // /proc/self/stat's 22nd field is the start in clock ticks after boot; /proc/uptime the
  // seconds since boot. The command (field 2) is in parentheses and may hold spaces.
  std::ifstream stat("/proc/self/stat"), uptime("/proc/uptime");
  std::string line;
  double up = 0.0;
  const long ticks = sysconf(_SC_CLK_TCK);
  if (!std::getline(stat, line) || !(uptime >> up) || ticks <= 0) return std::nan("");
  const size_t close = line.rfind(')');
  if (close == std::string::npos) return std::nan("");
  std::istringstream rest(line.substr(close + 1));
  std::string field;
  for (int k = 3; k <= 22 && rest >> field; ++k)
    if (k == 22) return up - std::stod(field) / static_cast<double>(ticks);
  return std::nan("");
}

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
