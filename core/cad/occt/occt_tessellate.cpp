#include "core/cad/occt/occt_tessellate.h"

#include <tbb/parallel_for.h>

#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <IMeshTools_Parameters.hxx>
#include <Standard_Failure.hxx>
#include <Standard_OutOfMemory.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>

#include "core/cad/occt/face_error.h"
#include "core/cad/occt/occt_model.h"

namespace surfinspect::occt {
namespace {

// Meshing passes at most; each cuts the deflection by the measured overshoot.
constexpr int kMaxPasses = 6;

std::vector<MeshedFace> MeshAndMeasure(const OcctModel& model, double deflection, double angle_deg,
                                       double tol) {
  BRepTools::Clean(model.shape);
  MeshShape(model.shape, deflection, angle_deg);
  std::vector<MeshedFace> faces(model.faces.size());
  tbb::parallel_for(std::size_t{0}, faces.size(), [&](std::size_t i) {
    faces[i] = MeasureMeshedFace(model.faces[i].face, tol / 4);
  });
  return faces;
}

double Worst(const std::vector<MeshedFace>& faces) {
  double worst = 0;
  for (const MeshedFace& f : faces) worst = std::max(worst, f.error_mm);
  return worst;
}

// The B-rep's own gap between an edge's curve and its faces' surfaces, as
// the file states it: a floor under any measured tessellation error.
double LargestEdgeTolerance(const OcctModel& model) {
  double worst = 0;
  for (const ModelFace& f : model.faces)
    for (TopExp_Explorer e(f.face, TopAbs_EDGE); e.More(); e.Next())
      worst = std::max(worst, BRep_Tool::Tolerance(TopoDS::Edge(e.Current())));
  return worst;
}

uint32_t Group(MeshGroups* g, std::map<std::string, uint32_t>* index, const std::string& name) {
  auto [it, added] = index->emplace(name, static_cast<uint32_t>(g->names.size()));
  if (added) g->names.push_back(name);
  return it->second;
}

// One mesh of all faces; face i's triangles in face:i+1 and its other groups.
void Assemble(const OcctModel& model, const std::vector<MeshedFace>& faces, CadTessellation* out) {
  std::map<std::string, uint32_t> index;
  MeshGroups& g = out->groups;
  for (std::size_t i = 0; i < faces.size(); ++i) Group(&g, &index, "face:" + std::to_string(i + 1));
  for (std::size_t i = 0; i < faces.size(); ++i) {
    const ModelFace& mf = model.faces[i];
    std::vector<uint32_t> also;
    if (!mf.name.empty()) also.push_back(Group(&g, &index, "name:" + mf.name));
    if (!mf.color.empty()) also.push_back(Group(&g, &index, "color:" + mf.color));
    also.push_back(Group(&g, &index, "body:" + model.bodies[mf.body]));
    std::sort(also.begin(), also.end());
    const auto base = static_cast<uint32_t>(out->mesh.vertices.size());
    out->mesh.vertices.insert(out->mesh.vertices.end(), faces[i].nodes.begin(),
                              faces[i].nodes.end());
    for (const auto& t : faces[i].triangles) {
      const auto id = static_cast<uint32_t>(out->mesh.triangles.size());
      out->mesh.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
      g.triangle_group.push_back(static_cast<uint32_t>(i));
      for (uint32_t a : also) g.more.push_back({id, a});
    }
  }
}

absl::StatusOr<CadTessellation> Tessellate(const std::string& path,
                                           const TessellationSettings& settings) {
  const auto start = std::chrono::steady_clock::now();
  auto model = ReadOcctModel(path, settings.body);
  if (!model.ok()) return model.status();
  const double tol = settings.chord_tolerance_mm;
  double deflection = tol;
  std::vector<MeshedFace> faces;
  int passes = 0;
  double previous = INFINITY;
  for (;;) {
    faces = MeshAndMeasure(*model, deflection, settings.angular_tolerance_deg, tol);
    ++passes;
    const double worst = Worst(faces);
    const bool stalled = worst > 0.9 * previous;  // finer meshing no longer helps
    previous = worst;
    std::size_t triangles = 0, over = 0;
    for (const MeshedFace& f : faces) triangles += f.triangles.size(), over += f.error_mm > tol;
    std::fprintf(
        stderr,
        "pass %d: deflection %.3g mm, %zu triangles, measured %.3g mm, %zu faces over %.3g mm\n",
        passes, deflection, triangles, worst, over, tol);
    if (worst <= tol || passes == kMaxPasses || stalled) break;
    // The chord error of a smooth surface grows about linearly with the
    // deflection asked for: aim 20% under the tolerance, cut at most 10x.
    deflection *= std::clamp(0.8 * tol / worst, 0.1, 0.8);
  }
  CadTessellation out;
  Assemble(*model, faces, &out);
  CadReport& r = out.report;
  r.source = std::filesystem::path(path).filename().string();
  r.format = model->format;
  r.declared_unit = model->declared_unit;
  r.bodies = model->bodies;
  r.body = settings.body;
  r.faces = faces.size();
  r.triangles = out.mesh.num_triangles();
  r.chord_tolerance_mm = tol;
  r.angular_tolerance_deg = settings.angular_tolerance_deg;
  r.deflection_mm = deflection;
  r.passes = passes;
  for (const MeshedFace& f : faces) r.face_error_mm.push_back(f.error_mm);
  r.tessellation_error_mm = Worst(faces);
  r.tolerance_held = r.tessellation_error_mm <= tol;
  r.brep_tolerance_mm = LargestEdgeTolerance(*model);
  r.bounds_mm = ComputeBounds(out.mesh);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (out.mesh.triangles.empty())
    return absl::InvalidArgumentError(path + ": OpenCASCADE made no triangles of its faces");
  return out;
}

}  // namespace

void MeshShape(const TopoDS_Shape& shape, double deflection_mm, double angle_deg) {
  IMeshTools_Parameters mesh;
  mesh.Deflection = deflection_mm;
  mesh.Angle = angle_deg * M_PI / 180;
  mesh.InParallel = true;
  // Delabella's sweep instead of the default Watson insertion: Watson's
  // circle search dominates on faces with many holes, the case
  // bench/cad_bench.cpp measures against OCCT's defaults. Same nodes; where
  // four or more lie on one circle (a square) it may pick the other diagonal.
  mesh.MeshAlgo = IMeshTools_MeshAlgoType_Delabella;
  BRepMesh_IncrementalMesh(shape, mesh);
}

// OCCT reports failures as Standard_Failure, which is no std::exception.
absl::StatusOr<CadTessellation> TessellateCad(const std::string& path,
                                              const TessellationSettings& settings) {
  try {
    return Tessellate(path, settings);
  } catch (const Standard_OutOfMemory&) {
    return absl::ResourceExhaustedError(path + ": out of memory in OpenCASCADE");
  } catch (const Standard_Failure& e) {
    return absl::InvalidArgumentError(path + ": OpenCASCADE failed: " + e.GetMessageString() +
                                      " (" + e.DynamicType()->Name() + ")");
  } catch (const std::bad_alloc&) {
    return absl::ResourceExhaustedError(path + ": out of memory in OpenCASCADE");
  }
}

}  // namespace surfinspect::occt
