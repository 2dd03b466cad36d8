// ListHoles (core/plan/cad_holes.h) on real STEP solids, as a user gets them
// (tessellated, written as OBJ, read back with shared vertices: a closed
// mesh), against OpenCASCADE's exact geometry: every hole the mesh lists
// lies on the axis of a cylindrical face of the file whose material is
// outside it (a hole, not a boss), with that cylinder's diameter. On the
// bracket, whose every concave cylinder is a through hole with sharp rims,
// each is found at both ends; on the NIST part (fillets are concave
// cylinders too, without rims) the count is pinned.
#include <gtest/gtest.h>

#include <BRepAdaptor_Surface.hxx>
#include <BRepLProp_SLProps.hxx>
#include <BRepTools.hxx>
#include <gp_Cylinder.hxx>

#include "core/cad/occt/occt_model.h"
#include "core/cad/occt/occt_tessellate.h"
#include "core/io/atomic_file.h"
#include "core/io/io_mesh.h"
#include "core/io/obj_groups.h"
#include "core/plan/cad_holes.h"
#include "tests/core/cad/cad_test_files.h"
#include "tests/support/temp_dir.h"

namespace surfinspect::occt {
namespace {

using testing::RealCad;

// A cylindrical face of the file: its axis and radius, and whether the
// material lies outside it (the face's outward normal points to the axis).
struct Cylinder {
  Eigen::Vector3d point, direction;
  double radius = 0;
  bool hole = false;
};

std::vector<Cylinder> CylindersOf(const OcctModel& model) {
  std::vector<Cylinder> out;
  for (const ModelFace& f : model.faces) {
    const BRepAdaptor_Surface surface(f.face);
    if (surface.GetType() != GeomAbs_Cylinder) continue;
    const gp_Cylinder c = surface.Cylinder();
    const gp_Ax1 axis = c.Axis();
    Cylinder cyl{{axis.Location().X(), axis.Location().Y(), axis.Location().Z()},
                 {axis.Direction().X(), axis.Direction().Y(), axis.Direction().Z()},
                 c.Radius()};
    double u0, u1, v0, v1;
    BRepTools::UVBounds(f.face, u0, u1, v0, v1);
    BRepLProp_SLProps props(surface, (u0 + u1) / 2, (v0 + v1) / 2, 1, 1e-9);
    if (!props.IsNormalDefined()) continue;
    gp_Dir n = props.Normal();
    if (f.face.Orientation() == TopAbs_REVERSED) n.Reverse();
    const gp_Pnt p = props.Value();
    Eigen::Vector3d radial = Eigen::Vector3d(p.X(), p.Y(), p.Z()) - cyl.point;
    radial -= radial.dot(cyl.direction) * cyl.direction;
    cyl.hole = Eigen::Vector3d(n.X(), n.Y(), n.Z()).dot(radial) < 0;
    out.push_back(cyl);
  }
  return out;
}

double OffAxis(const Cylinder& c, const Eigen::Vector3d& p) {
  const Eigen::Vector3d d = p - c.point;
  return (d - d.dot(c.direction) * c.direction).norm();
}

// The part as `surfinspect cad` writes it and every command reads it.
TriangleMesh ClosedMesh(const std::string& name, const std::string& dir) {
  TessellationSettings s;
  s.chord_tolerance_mm = 0.01;
  auto t = TessellateCad(RealCad(name), s);
  EXPECT_TRUE(t.ok()) << t.status();
  if (!t.ok()) return {};
  const std::string obj = dir + "/part.obj";
  auto text = ObjWithGroups(t->mesh, t->groups);
  EXPECT_TRUE(text.ok() && WriteStringAtomically(obj, *text).ok());
  auto mesh = ReadMesh(obj);
  EXPECT_TRUE(mesh.ok()) << mesh.status();
  return mesh.ok() ? *std::move(mesh) : TriangleMesh{};
}

struct Expect {
  const char* name;
  std::size_t rims;  // listed
  bool complete;     // every concave cylinder is a through hole: found at both ends
};

class RealSolid : public ::testing::TestWithParam<Expect> {};

TEST_P(RealSolid, EveryListedHoleIsAConcaveCylinderOfTheFile) {
  SKIP_WITHOUT_REAL_CAD();
  const testing::TempDir dir;
  const TriangleMesh mesh = ClosedMesh(GetParam().name, dir.path());
  const auto model = ReadOcctModel(RealCad(GetParam().name), "");
  ASSERT_TRUE(model.ok()) << model.status();
  const std::vector<Cylinder> cylinders = CylindersOf(*model);
  const std::vector<CadHole> holes = ListHoles(mesh);
  std::size_t concave = 0;
  for (const Cylinder& c : cylinders) concave += c.hole;
  std::cout << GetParam().name << ": " << holes.size() << " rims listed; the file has "
            << cylinders.size() << " cylindrical faces, " << concave << " of them holes\n";
  EXPECT_EQ(holes.size(), GetParam().rims);
  std::vector<int> rims_on(cylinders.size(), 0);
  for (const CadHole& h : holes) {
    EXPECT_TRUE(h.rim) << "a closed mesh has no boundary loop";
    const Cylinder* match = nullptr;
    for (std::size_t k = 0; k < cylinders.size(); ++k) {
      const Cylinder& c = cylinders[k];
      if (!c.hole || OffAxis(c, h.position_mm) > 1e-3 || std::abs(c.direction.dot(h.axis)) < 0.9999)
        continue;
      match = &c;
      ++rims_on[k];
    }
    ASSERT_NE(match, nullptr) << "hole at " << h.position_mm.transpose() << " axis "
                              << h.axis.transpose() << " is on no concave cylinder";
    // The rim's vertices lie on the exact circle (the chord tolerance is
    // the sagitta between them): the fitted diameter is the cylinder's.
    EXPECT_NEAR(h.diameter_mm, 2 * match->radius, 2e-3);
  }
  for (std::size_t k = 0; k < cylinders.size() && GetParam().complete; ++k) {
    EXPECT_EQ(rims_on[k], cylinders[k].hole ? 2 : 0)
        << "cylinder " << k << " at " << cylinders[k].point.transpose();
  }
}

INSTANTIATE_TEST_SUITE_P(Real, RealSolid,
                         ::testing::Values(Expect{"bug3883_xr2-ct-214_l-bracket.stp", 8, true},
                                           Expect{"nist_ctc_01_asme1_ap242-e1.stp", 18, false}));

}  // namespace
}  // namespace surfinspect::occt
