#pragma once
// Audit and training: verify a saved plan (inputs, hash chain, replay), read its timeline, and
// compare a trainee's plan with an expert's (time per step, implant agreement).
#include <array>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/quality/check_implant.h"
#include "cranioplan/algorithms/quality/compare_implants.h"
#include "cranioplan/algorithms/quality/soft_tissue_check.h"
#include "cranioplan/sessions/session.h"

namespace cranioplan {

struct VerifyCheck {
  std::string name;  ///< "inputs", "hash chain", "commands", "replay"
  bool ok = false;
  std::string detail;  ///< plain words
};

struct VerifyReport {
  std::vector<VerifyCheck> checks;
  bool ok() const;
};

/// Inputs' SHA-256, the journal's hash chain, the command lists against the journal, and a
/// replay that reproduces every recorded export hash. Throws SessionError / InputError only when
/// the file cannot be read as a session at all (not JSON, unknown schema, ...).
VerifyReport verify_session(const std::string& path);

/// Wall-clock time spent in each wizard step, from the journal: the time from one event to the
/// next counts for the step of the later event (notes count for the step before them). Idle
/// gaps longer than `idle_cap_s` count as `idle_cap_s`.
struct StepDurations {
  std::array<double, kStepCount + 1> seconds{};  ///< by step number (kLoadStep..kExportStep)
  double total = 0.0;
};
StepDurations step_durations(const SessionHeader& header, const std::vector<JournalEntry>& journal,
                             double idle_cap_s = 300.0);

/// One line of the timeline.
struct AuditRow {
  int seq = 0;
  std::string time;
  std::string user;
  std::string event;  ///< do, undo, redo, merge
  int step = 0;
  std::string what;    ///< describe() of the command done, undone or redone
  std::string params;  ///< compact JSON of the parameters (do and merge)
  double duration_ms = 0;
  bool undone = false;  ///< a do whose command is not in the final plan
};
std::vector<AuditRow> audit_rows(const SessionDocument& doc);
std::string audit_text(const SessionDocument& doc);
std::string audit_html(const SessionDocument& doc, const VerifyReport* verify = nullptr);

struct TrainingReport {
  std::string trainee_user, reference_user;
  StepDurations trainee, reference;
  std::optional<CompareResult> agreement;  ///< trainee implant vs reference implant
  double trainee_volume_mm3 = 0.0, reference_volume_mm3 = 0.0;
  std::string note;  ///< why there is no agreement, when there is none
};
/// Times from both journals; agreement from both sessions' final implants (boundary Dice near
/// the trainee's skull).
TrainingReport training_report(const Session& trainee, const Session& reference,
                               const CompareParams& params = {});
std::string training_report_text(const TrainingReport& report);
std::string training_report_html(const TrainingReport& report);

/// The quality report as an HTML table and its problems as a list (the wizard's Quality panel
/// and its export check).
/// With `tissue` (the plan has a CT), also the soft tissue under the implant
/// (check_soft_tissue), a warning when the implant lies in it.
std::string quality_report_html(const QualityReport& report,
                                const SoftTissueCheck* tissue = nullptr);

/// What a person can try when the quality check refuses an implant built with `params`, one
/// sentence each in the wizard's words (empty when it is printable): the fit to the bone for
/// gaps, overlap and crossing triangles; the markers and smoothing when the fit is on already;
/// the thickness for thin material; the tabs and holes for theirs.
std::vector<std::string> quality_advice(const QualityReport& report, const ImplantParams& params);

/// The quality check's verdict in a few lines for a wizard page: printable, or what is wrong
/// (the report's reasons) and what to try (quality_advice); with `tissue`, a finding on the CT
/// (brain or dura in the implant's place) said beside "printable" as one to check before
/// approval.
std::string quality_verdict_html(const QualityReport& report, const ImplantParams& params,
                                 const SoftTissueCheck* tissue = nullptr);

/// A picture in the design report: its caption, its file (beside the report) and what it
/// shows (the implant on the skull, its thickness map, or a CT slice through it).
struct ReportImage {
  enum class Kind { View, Thickness, Slice };
  std::string caption, file;
  Kind kind = Kind::View;
};
/// The design report for the surgeon's sign-off (HTML laid out for A4: identity, verdict,
/// implant, quality and approval on the first page; the pictures on the next ones). Identity:
/// the case, who planned it and when, the last change, the program's version. The implant's
/// material and dimensions (extent along its principal axes, area, volume, mass), the quality
/// table with every finding (with `tissue`, the soft tissue in its place on the CT), the
/// perforations and the fixation tabs, the inputs' SHA-256, the plan's hash (the journal's last)
/// and the implant's STL hash; the approval (or that there is none, or why it was withdrawn)
/// with what is approved. The plan must have an implant.
std::string design_report_html(const Session& session, const std::vector<ReportImage>& images,
                               const std::string& program_version,
                               const SoftTissueCheck* tissue = nullptr);

}  // namespace cranioplan
