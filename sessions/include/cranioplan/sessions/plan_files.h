#pragma once
// JSON forms of the plan's pieces (landmarks, planes, transforms, reports) and their files.
// The same forms are the payloads of session commands and the CLI's --json output.
#include <nlohmann/json.hpp>
#include <string>

#include "cranioplan/algorithms/alignment/fit_sagittal_plane.h"
#include "cranioplan/algorithms/alignment/register_icp.h"
#include "cranioplan/algorithms/implant/build_implant.h"
#include "cranioplan/algorithms/io/extract_bone_surface.h"
#include "cranioplan/algorithms/io/mesh_report.h"
#include "cranioplan/algorithms/quality/check_implant.h"
#include "cranioplan/algorithms/quality/compare_implants.h"
#include "cranioplan/algorithms/quality/soft_tissue_check.h"
#include "cranioplan/model/landmarks.h"
#include "cranioplan/model/plane.h"
#include "cranioplan/model/rigid_transform.h"

namespace cranioplan {

using Json = nlohmann::ordered_json;

Json to_json(const Eigen::Vector3d& v);
Json to_json(const Plane& plane);       ///< {"normal":[..],"offset_mm":d}
Json to_json(const std::vector<Plane>& planes);  ///< a list of planes
Json to_json(const RigidTransform& t);  ///< {"rotation":[[..],[..],[..]],"translation":[..]}
Json to_json(const Landmarks& lm);
Json to_json(const MeshReport& r);
Json to_json(const PlaneFit& fit);
Json to_json(const RegisterResult& r);
Json to_json(const QualityReport& q);
Json to_json(const CompareResult& c);
Json to_json(const SoftTissueCheck& c);  ///< without the intruding voxels' positions

/// Readers of the same forms; `source` names the file in error messages. Throw InputError.
Eigen::Vector3d vector_from_json(const Json& j, const std::string& source, const std::string& what);
Plane plane_from_json(const Json& j, const std::string& source);
std::vector<Plane> planes_from_json(const Json& j, const std::string& source);
RigidTransform transform_from_json(const Json& j, const std::string& source);
Landmarks landmarks_from_json(const Json& j, const std::string& source);
/// The form to_json(RegisterResult) writes, read back; errors name `source`.
RegisterResult register_result_from_json(const Json& j, const std::string& source);
/// The form to_json(PlaneFit) writes, read back; errors name `source`.
PlaneFit plane_fit_from_json(const Json& j, const std::string& source);

/// Parses a JSON file; throws InputError for a missing file or invalid JSON (with the line).
Json read_json_file(const std::string& path);
/// Writes pretty JSON atomically (temporary file, flush, rename).
void write_json_file(const Json& j, const std::string& path);

/// Landmarks as JSON (to_json's form) or 3D Slicer markups (.mrk.json). Throws InputError.
Landmarks read_landmarks_file(const std::string& path);
void write_landmarks_file(const Landmarks& landmarks, const std::string& path);
Plane read_plane_file(const std::string& path);

}  // namespace cranioplan
