// The plan's alignment block (PlanAlignment in inspection_plan.h): its JSON
// form, its validation against the plan and the part, and the RPS
// references at their nominal places with the directions each locks.
//
// An RPS set is refused unless it locks all six degrees of freedom: the
// analysis of core/registration/rigid_dofs.h on the nominal references,
// whatever the scan will show, so that a bad drawing is refused when the
// plan is loaded and the message names the free motions.
#pragma once

#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "absl/status/status.h"
#include "absl/status/statusor.h"
#include "core/plan/inspection_plan.h"
#include "core/registration/rps_fit.h"
#include "core/types/triangle_mesh.h"

namespace surfinspect {

// {"mode": "calibrated" | "rps" | "best_fit", "references": [{"name",
// "hole"} | {"name", "position_mm", "radius_mm"}], "regions": [names],
// "locked": ["tx" .. "rz"], "max_correction_mm", "max_correction_deg"};
// keys and types checked, the field named (`path` is the block's).
absl::StatusOr<PlanAlignment> ParsePlanAlignment(const nlohmann::json& json,
                                                 const std::string& path);
nlohmann::json PlanAlignmentJson(const PlanAlignment& alignment);

// InvalidArgument naming the field: a mode's missing or extra parts, a
// reference naming no plan hole, a non-finite or non-positive number,
// duplicate names, a region not in the plan, all six degrees locked, or an
// RPS set that leaves motions free ("... leave free: rotation about z").
absl::Status ValidatePlanAlignment(const InspectionPlan& plan, const TriangleMesh& part,
                                   const std::string& path);

// One per plan.alignment.references entry, in order: nominal_mm and
// measured_mm both at the nominal place (a hole's centre, or the surface
// point moved onto the CAD), the directions it locks (a hole's e1 and e2, a
// slot's e2, the CAD normal at a surface point). The plan was validated.
std::vector<RpsReference> NominalRpsReferences(const InspectionPlan& plan,
                                               const TriangleMesh& part);

// The degrees of freedom "tx" .. "rz" name, in Dof order.
extern const char* const kDofKeys[kRigidDofs];
// Locks the one `key` names; false for a key not in kDofKeys.
bool LockDofNamed(const std::string& key, LockedDofs* locked);

}  // namespace surfinspect
