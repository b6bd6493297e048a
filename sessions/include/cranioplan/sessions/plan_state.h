#pragma once
// The plan's state: a pure function of the inputs and the effective commands. Heavy results
// (meshes, locators, the implant) are shared immutable pieces, so a state is cheap to copy and
// the session keeps one per command for instant undo.
#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"
#include "cranioplan/algorithms/alignment/register_icp.h"
#include "cranioplan/algorithms/geometry/surface_locator.h"
#include "cranioplan/algorithms/implant/build_implant.h"
#include "cranioplan/algorithms/implant/casting_mould.h"
#include "cranioplan/algorithms/io/load_skull.h"
#include "cranioplan/algorithms/planning/detect_defect.h"
#include "cranioplan/algorithms/quality/check_implant.h"
#include "cranioplan/model/landmarks.h"
#include "cranioplan/model/marker.h"
#include "cranioplan/model/mesh.h"
#include "cranioplan/sessions/command.h"
#include "cranioplan/sessions/steps.h"

namespace cranioplan {

/// A skull loaded from a file with its locator, built once and shared by every state that uses
/// it. The loaded skull is built in place: OpenMesh meshes have no move constructor, so
/// std::move copies them, and each copy of a skull costs its whole size again
/// (docs/BENCHMARKS.md, "Where the memory goes, and what bounds it").
struct SharedSurface {
  SharedSurface(const std::string& path, const ExtractBoneSurfaceParams& import);
  SharedSurface(const SharedSurface&) = delete;
  SharedSurface& operator=(const SharedSurface&) = delete;
  const LoadedSkull loaded;  ///< how it was read (description, warnings) and its mesh
  const SkullMesh& mesh;     ///< loaded.mesh
  SurfaceLocator locator;
  const std::string path;                 ///< the file read (found where the plan says)
  const ExtractBoneSurfaceParams import;  ///< how (a CT's threshold, series, ...)
};

/// The mirrored skull where the plan has put it: not a mesh of its own but the skull itself,
/// moved by `placement` (the reflection across the plane, then the registration and any hand
/// moves: an improper motion). A mirrored copy is as large as the skull, too much to keep one
/// per registration in the session's history. The view draws the skull's mesh moved by
/// `placement`; the locator answers in place (the skull's own tree, moved).
struct MovedSurface {
  std::shared_ptr<const SharedSurface> skull;  ///< the skull's mesh and tree
  RigidTransform placement;                    ///< skull → the mirror where the plan has put it
  SurfaceLocator locator;                      ///< the skull's tree moved by `placement`
};

struct SkullInput {
  std::string path;                                    ///< as recorded in the command
  std::string sha256;                                  ///< of the file's bytes
  std::shared_ptr<const SharedSurface> surface;        ///< how it was read: surface->loaded
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< of the vertices, mm
};

/// The implant and what is derived from it; the quality report (with the checks the build's
/// material and clearance zones ask for) is computed on first use.
class ImplantData {
 public:
  ImplantData(ImplantResult result, std::shared_ptr<const SkullInput> skull,
              QualityParams quality_params = {});
  /// The implant `build()` returns, kept where it is made (the result's mesh cannot be moved:
  /// taking a built result in copies it), and the quality checks `checks(result)` names.
  template <class Build, class Checks>
  ImplantData(Build&& build, Checks&& checks, std::shared_ptr<const SkullInput> skull)
      : result_(build()), skull_(std::move(skull)), quality_params_(checks(result_)) {}
  const QualityParams& quality_params() const { return quality_params_; }
  const ImplantResult& result() const { return result_; }
  /// SHA-256 of the binary STL bytes of the implant (what an .stl export writes), computed on
  /// first use (an export, an approval, the audit): a marker edit does not wait for it.
  const std::string& stl_sha256() const;
  const QualityReport& quality() const;

 private:
  ImplantResult result_;
  mutable std::once_flag sha_once_;
  mutable std::string stl_sha256_;
  std::shared_ptr<const SkullInput> skull_;
  QualityParams quality_params_;
  mutable std::once_flag quality_once_;
  mutable QualityReport quality_;
};

/// What an export writes: the format ("stl", "ply" or "3mf"); for a 3MF, the plan's hash at
/// the export (the journal's last hash), carried in its metadata with the implant's STL hash
/// (plan_description), and optionally a casting mould's halves as parts beside the implant.
struct PlanState;
/// A 3MF export's "Description" metadata: "Cranioplan plan SHA-256 …; implant STL SHA-256 …"
/// (the 3MF core's metadata names are the ones every reader accepts).
std::string plan_description(const std::string& plan_sha256, const std::string& implant_sha256);
struct ExportSpec {
  std::string format = "stl";
  std::string plan_sha256;
  std::optional<MouldParams> mould;
};
/// The bytes an export of the plan's implant (there must be one) writes; the mould's outer
/// half lies away from the skull's centre. A mould that cannot be made gives no bytes and says
/// why in `why`.
std::string export_bytes(const PlanState& state, const ExportSpec& spec, std::string* why);
/// The casting mould of a plan's implant, its outer half away from the skull's centre (none:
/// the implant's centroid 80 mm up): the one a 3MF export with `params` holds.
MouldResult mould_of(const SkullMesh& implant, const SkullMesh* skull, const MouldParams& params);

struct ExportRecord {
  std::string path;
  std::string format;           ///< "stl", "ply" or "3mf"
  std::string recorded_sha256;  ///< what the command says was written
  std::string replayed_sha256;  ///< the bytes this state's implant encodes to
  std::string implant_sha256;   ///< the implant's STL hash at the time of the export
};

/// A CT attached to a plan made from a mesh (attach_ct), shown in the slice views.
struct AttachedCt {
  std::string path;           ///< the file read (found where the plan says)
  std::string recorded_path;  ///< as the command records it
  std::string sha256;
  ExtractBoneSurfaceParams import;       ///< threshold, series; read with these
  double median_mm = 0.0, p90_mm = 0.0;  ///< the skull's distance to its bone surface
  std::string message;
};

struct PlanState {
  // Step 1
  std::shared_ptr<const SkullInput> skull;
  std::optional<AttachedCt> ct;  ///< a mesh plan's CT (a CT plan's is its skull's file)
  // Step 2
  Landmarks landmarks;
  std::optional<Plane> plane;
  std::optional<PlaneFit> plane_fit;  ///< diagnostics of the last fit
  // Step 3
  bool mirror_requested = false;  ///< mirrored: the mirror is the skull reflected across `plane`
  std::optional<RegisterParams> register_params;  ///< re-run when the plane changes
  std::optional<RegisterResult> registration;
  RigidTransform manual;                         ///< hand moves, applied after the registration
  std::shared_ptr<const MovedSurface> mirrored;  ///< reflected, then registration, then manual
  // Step 4
  std::optional<Plane> clip_plane;
  // Steps 5, 6, 8
  std::vector<Marker> markers;
  int next_marker_id = 1;                        ///< ids are never reused
  std::optional<Eigen::Vector3d> defect_center;  ///< from the last proposal
  std::string proposal_message;
  /// From the last proposal: the shape model file it was guided by, as recorded (empty: none).
  std::string proposal_shape_model;
  /// From the last proposal: the parameters it was made with, and how its shape model was
  /// fitted and weighed (the defaults without one), as recorded: a proposal made again in the
  /// wizard asks the same.
  ProposeParams proposal_params;
  ShapePriorParams proposal_prior;
  /// From the last proposal: stretches of the rim no ray saw, where the outline between the
  /// edge markers is interpolated (the view draws them for the surgeon to check).
  std::vector<RimStretch> unseen_rim;
  /// From the last proposal: where the scan ended across the opening (DefectRegion::scan_ends);
  /// the implant ends there unless its parameters say where.
  std::vector<Plane> scan_ends;
  // Step 7
  std::optional<ImplantParams> implant_params;  ///< rebuilt after every marker change
  std::shared_ptr<const ImplantData> implant;
  // Step 9
  std::vector<ExportRecord> exports;
  /// The surgeon's sign-off of the implant with this STL hash (approve); withdrawn, with the
  /// reason in `approval_withdrawn`, when the implant changes.
  struct Approval {
    std::string by, role, implant_sha256;
  };
  std::optional<Approval> approval;
  std::string approval_withdrawn;
  // Wizard
  std::array<bool, kStepCount + 1> acknowledged{};  ///< steps done by hand (mirror, clip, smooth)
  std::map<int, std::string> stale;                 ///< step → why its results were recomputed
  int current_step = kLoadStep;
  std::vector<std::string> notes;
  std::string message;  ///< what the last command did, or why it had no effect

  RigidTransform mirror_transform() const;
  const Marker* find_marker(int id) const;
};

struct WizardStep {
  int number;
  const char* title;
  const char* instructions;
};
/// The plan's CT: the one attached to a plan made from a mesh, or the volume its skull was
/// imported from (its `median_mm`, `p90_mm` then 0: the skull is its bone surface); none for a
/// mesh plan without one.
std::optional<AttachedCt> plan_ct(const PlanState& state);

/// A plane fit in a person's words: its symmetry RMS and inliers, and whether that is good
/// (RMS ≤ 1.5 mm with ≥ 60 % inliers: the two sides agree as a normal skull's do), fair (RMS
/// ≤ 3 mm with ≥ 40 %: check the plane on the face) or poor (place the landmarks again or
/// adjust the plane by hand).
std::string describe_plane_fit(const PlaneFit& fit);
/// A registration's verdict: good (RMS ≤ 1.5 mm with ≥ 60 % paired), fair (≤ 3 mm with
/// ≥ 40 %) or poor, with what to do.
const char* registration_verdict(const RegisterResult& result);
/// A landmark's name as a person says it ("orbit_left": "left orbit").
std::string landmark_words(const std::string& name);

/// The nine steps of the wizard, 1..9.
const std::array<WizardStep, kStepCount>& wizard_steps();
/// Whether step `step` (1..9) is done; when not, `missing` says what is missing.
bool step_complete(const PlanState& state, int step, std::string* missing = nullptr);
/// Whether every step before `step` is done; when not, `why` names the first that is not.
bool step_unlocked(const PlanState& state, int step, std::string* why = nullptr);
/// The wizard step a command belongs to (marker edits: the marker's step); 0 for notes.
int command_step(const PlanState& state, const Command& command);

struct ApplyContext {
  std::string session_dir;  ///< relative and moved input paths are looked up here too
};

struct ApplyOutcome {
  bool accepted = false;
  std::string message;  ///< why it was refused, or what it did
  PlanState state;      ///< the new state (the old one when refused)
  /// What the command found that a replay must reuse rather than recompute, merged into the
  /// command's params when it is recorded: "result" of fit_plane (the fit), register (the
  /// registration) and propose_markers (the markers); "registration" of fit_plane and
  /// adjust_plane when the plane change registered the mirror again.
  /// Empty when there is nothing to record or the command already carried it.
  Json record = Json::object();
};

struct MarkerProposal;
/// What a propose_markers command records as its "result" for `proposal` (whether markers were
/// proposed, the markers with their ids, the opening's centre, the message), and applies. A
/// caller that has proposed already (autoplan_session, which found the opening to register
/// around it) puts it in the command, so the opening is not looked for twice.
Json proposal_result(const MarkerProposal& proposal);

/// Applies one command. A command of a locked step, or one that refers to something that does
/// not exist (a marker id, a plane before landmarks), is refused. Bad inputs (a missing skull
/// file, a changed file) throw InputError/SessionError.
ApplyOutcome apply_command(const PlanState& before, const Command& command,
                           const ApplyContext& context = {});

}  // namespace cranioplan
