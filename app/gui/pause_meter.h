#pragma once
// The GUI thread's longest pauses: a timer every 10 ms notes how late each tick comes, i.e.
// how long the event loop was held (a window that does not repaint or answer the mouse).
#include <QElapsedTimer>
#include <QObject>
#include <QString>
#include <functional>
#include <vector>

class QTimer;

namespace cranioplan::gui {

/// Seconds since this process started, as the kernel records its start (a program that
/// starts itself again in place keeps it); NaN where /proc cannot tell.
double seconds_since_start();

class PauseMeter : public QObject {
  Q_OBJECT

 public:
  /// `context` names what the window was doing (its status line) when a pause ended.
  explicit PauseMeter(std::function<QString()> context, QObject* parent = nullptr);

  struct Pause {
    double ms = 0.0;    ///< how long the loop was held beyond the timer's interval
    double at_s = 0.0;  ///< when it ended, seconds from the start
    QString context;
  };
  /// The longest pauses so far, longest first (at most 5).
  const std::vector<Pause>& longest() const { return longest_; }
  /// "412 ms at 2.1 s (implant built…); …"
  QString summary() const;

 private:
  void tick();

  std::function<QString()> context_;
  QTimer* timer_;
  QElapsedTimer clock_;
  qint64 last_ns_ = 0;
  std::vector<Pause> longest_;
};

}  // namespace cranioplan::gui
