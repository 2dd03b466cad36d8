#include "core/cad/occt/occt_model.h"

#include <BRep_Builder.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IGESData_IGESModel.hxx>
#include <Quantity_Color.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPControl_Reader.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>

#include "absl/strings/str_cat.h"
#include "absl/strings/str_join.h"

namespace surfinspect::occt {
namespace {

std::string Upper(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  return s;
}

// A group name is one OBJ `g` token: blanks become '_'.
std::string Token(std::string s) {
  for (char& c : s)
    if (std::isspace(static_cast<unsigned char>(c))) c = '_';
  return s;
}

std::string NameOf(const TDF_Label& label) {
  Handle(TDataStd_Name) name;
  if (label.IsNull() || !label.FindAttribute(TDataStd_Name::GetID(), name)) return "";
  return Token(TCollection_AsciiString(name->Get()).ToCString());
}

std::string ColorOf(const Handle(XCAFDoc_ColorTool) & colors, const TDF_Label& label) {
  Quantity_Color c;
  if (label.IsNull() || !(colors->GetColor(label, XCAFDoc_ColorSurf, c) ||
                          colors->GetColor(label, XCAFDoc_ColorGen, c)))
    return "";
  Standard_Real rgb[3];
  c.Values(rgb[0], rgb[1], rgb[2], Quantity_TOC_sRGB);
  char hex[8];
  std::snprintf(hex, sizeof hex, "#%02x%02x%02x", static_cast<int>(std::lround(rgb[0] * 255)),
                static_cast<int>(std::lround(rgb[1] * 255)),
                static_cast<int>(std::lround(rgb[2] * 255)));
  return hex;
}

struct Walker {
  Handle(XCAFDoc_ShapeTool) shapes;
  Handle(XCAFDoc_ColorTool) colors;
  std::string wanted;  // body name, "" for all
  OcctModel* model;
  std::set<std::string> names;

  std::string UniqueBody(std::string name) {
    if (name.empty()) name = absl::StrCat("body-", model->bodies.size() + 1);
    std::string unique = name;
    for (int n = 2; !names.insert(unique).second; ++n) unique = absl::StrCat(name, "#", n);
    return unique;
  }

  void Body(const TDF_Label& product, const TopLoc_Location& loc, const std::string& color) {
    const TopoDS_Shape shape = XCAFDoc_ShapeTool::GetShape(product);
    TopTools_IndexedMapOfShape faces;
    TopExp::MapShapes(shape, TopAbs_FACE, faces);
    if (faces.IsEmpty()) return;  // PMI presentation, wires, points
    const std::string body = UniqueBody(NameOf(product));
    model->bodies.push_back(body);
    if (!wanted.empty() && body != wanted) return;
    const std::string body_color = color.empty() ? ColorOf(colors, product) : color;
    for (int i = 1; i <= faces.Extent(); ++i) {
      const TopoDS_Face& face = TopoDS::Face(faces(i));
      ModelFace f{TopoDS::Face(face.Moved(loc)), static_cast<uint32_t>(model->bodies.size() - 1),
                  "", ""};
      TDF_Label sub;
      if (shapes->FindSubShape(product, face, sub))
        f.name = NameOf(sub), f.color = ColorOf(colors, sub);
      if (f.color.empty()) f.color = body_color;
      model->faces.push_back(std::move(f));
    }
  }

  void Walk(const TDF_Label& label, const TopLoc_Location& loc, const std::string& color) {
    TDF_Label ref = label;
    TopLoc_Location here = loc;
    std::string instance_color = color;
    if (XCAFDoc_ShapeTool::IsReference(label)) {
      XCAFDoc_ShapeTool::GetReferredShape(label, ref);
      here = loc * XCAFDoc_ShapeTool::GetLocation(label);
      if (const std::string c = ColorOf(colors, label); !c.empty()) instance_color = c;
    }
    if (XCAFDoc_ShapeTool::IsAssembly(ref)) {
      TDF_LabelSequence components;
      XCAFDoc_ShapeTool::GetComponents(ref, components);
      for (int i = 1; i <= components.Length(); ++i) Walk(components(i), here, instance_color);
      return;
    }
    Body(ref, here, instance_color);
  }
};

// Transfers the file into an XCAF document; sets format and declared unit.
absl::Status Transfer(const std::string& path, Handle(TDocStd_Document) doc, OcctModel* model) {
  std::string ext = Upper(std::filesystem::path(path).extension().string());
  const bool iges = ext == ".IGES" || ext == ".IGS";
  model->format = iges ? "IGES" : "STEP";
  auto unreadable = [&](const char* what) {
    return absl::InvalidArgumentError(
        absl::StrCat(path, ": not a readable ", model->format, " file (", what, ")"));
  };
  if (iges) {
    IGESCAFControl_Reader reader;
    reader.SetColorMode(true), reader.SetNameMode(true);
    if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return unreadable("read failed");
    if (!reader.Transfer(doc)) return unreadable("transfer failed");
    if (Handle(IGESData_IGESModel) m = reader.IGESModel();
        !m.IsNull() && !m->GlobalSection().UnitName().IsNull())
      model->declared_unit = Upper(m->GlobalSection().UnitName()->ToCString());
    return absl::OkStatus();
  }
  STEPCAFControl_Reader reader;
  reader.SetColorMode(true), reader.SetNameMode(true), reader.SetLayerMode(false);
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return unreadable("read failed");
  if (!reader.Transfer(doc)) return unreadable("transfer failed");
  TColStd_SequenceOfAsciiString lengths, angles, solid_angles;
  reader.ChangeReader().FileUnits(lengths, angles, solid_angles);
  if (lengths.Length() > 0) model->declared_unit = Upper(lengths(1).ToCString());
  return absl::OkStatus();
}

}  // namespace

absl::StatusOr<OcctModel> ReadOcctModel(const std::string& path, const std::string& body) {
  OcctModel model;
  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  if (auto st = Transfer(path, doc, &model); !st.ok()) return st;
  Walker walker{XCAFDoc_DocumentTool::ShapeTool(doc->Main()),
                XCAFDoc_DocumentTool::ColorTool(doc->Main()),
                body,
                &model,
                {}};
  TDF_LabelSequence free_shapes;
  walker.shapes->GetFreeShapes(free_shapes);
  for (int i = 1; i <= free_shapes.Length(); ++i) walker.Walk(free_shapes(i), {}, "");
  if (model.bodies.empty()) return absl::InvalidArgumentError(path + ": holds no face to mesh");
  if (model.faces.empty())
    return absl::InvalidArgumentError(absl::StrCat(path, ": no body \"", body, "\" (the file has ",
                                                   absl::StrJoin(model.bodies, ", "), ")"));
  BRep_Builder builder;
  builder.MakeCompound(model.shape);
  for (const ModelFace& f : model.faces) builder.Add(model.shape, f.face);
  return model;
}

}  // namespace surfinspect::occt
