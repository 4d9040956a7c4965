// The OpenCASCADE module's writing side (see cad_module.h): an assembly of prisms and sheets
// built as B-rep, placed in an XDE document with names and colours, written as STEP. What
// `lodforge generate cad -o X.step` uses, so CAD scale tests need no download.
#include <fmt/format.h>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepPrimAPI_MakePrism.hxx>
#include <BRep_Builder.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <Quantity_ColorRGBA.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <ShapeFix_Face.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Iterator.hxx>
#include <TopoDS_Shell.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_LayerTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Ax2.hxx>
#include <gp_Circ.hxx>
#include <gp_Trsf.hxx>

#include <mutex>

#include "lodforge/io/cad/cad_module.h"

namespace lodforge::cad {
namespace {

TopoDS_Wire makeWire(const Loop& loop, double z) {
  if (loop.radius > 0) {
    const gp_Circ circle(gp_Ax2(gp_Pnt(loop.points.at(0), loop.points.at(1), z), gp::DZ()),
                         loop.radius);
    return BRepBuilderAPI_MakeWire(BRepBuilderAPI_MakeEdge(circle).Edge()).Wire();
  }
  BRepBuilderAPI_MakePolygon polygon;
  for (std::size_t i = 0; i + 1 < loop.points.size(); i += 2)
    polygon.Add(gp_Pnt(loop.points[i], loop.points[i + 1], z));
  polygon.Close();
  return polygon.Wire();
}

// The face at z0 (holes cut out, orientations fixed by ShapeFix), swept to z1 when they differ.
TopoDS_Shape makePrism(const Prism& prism) {
  BRepBuilderAPI_MakeFace face(makeWire(prism.outer, prism.z0), true);
  for (const Loop& hole : prism.holes) face.Add(TopoDS::Wire(makeWire(hole, prism.z0).Reversed()));
  ShapeFix_Face fix(face.Face());
  fix.FixOrientation();
  fix.Perform();
  if (prism.z1 != prism.z0)
    return BRepPrimAPI_MakePrism(fix.Face(), gp_Vec(0, 0, prism.z1 - prism.z0)).Shape();
  // A sheet in a shell, as CAD systems write surface models: OCCT's STEP writer finds no
  // representation item (so drops the layer) for a bare face.
  BRep_Builder builder;
  TopoDS_Shell shell;
  builder.MakeShell(shell);
  builder.Add(shell, fix.Face());
  return shell;
}

// One solid where the prisms touch (a bolt's head and shank): OCCT's STEP writer drops the
// layer of a compound.
TopoDS_Shape makeShape(const ShapeSpec& spec) {
  if (spec.prisms.size() == 1) return makePrism(spec.prisms.front());
  TopTools_ListOfShape arguments, tools;
  for (std::size_t p = 0; p < spec.prisms.size(); ++p)
    (p == 0 ? arguments : tools).Append(makePrism(spec.prisms[p]));
  BRepAlgoAPI_Fuse fuse;
  fuse.SetArguments(arguments);
  fuse.SetTools(tools);
  fuse.Build();
  if (!fuse.IsDone()) throw std::runtime_error("OCCT could not fuse the prisms of " + spec.name);
  fuse.SimplifyResult();
  TopoDS_Shape fused = fuse.Shape();
  // A single solid comes back wrapped in a compound.
  if (fused.ShapeType() == TopAbs_COMPOUND) {
    TopoDS_Iterator only(fused);
    if (only.More()) {
      const TopoDS_Shape first = only.Value();
      only.Next();
      if (!only.More()) fused = first;
    }
  }
  return fused;
}

gp_Trsf transformOf(const double (&m)[16]) {
  gp_Trsf trsf;
  trsf.SetValues(m[0], m[4], m[8], m[12], m[1], m[5], m[9], m[13], m[2], m[6], m[10], m[14]);
  return trsf;
}

void write(const WriteRequest& request, WriteResult& result) {
  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  const Handle(XCAFDoc_ColorTool) colors = XCAFDoc_DocumentTool::ColorTool(doc->Main());
  const Handle(XCAFDoc_LayerTool) layers = XCAFDoc_DocumentTool::LayerTool(doc->Main());
  const TDF_Label root = shapes->NewShape();
  TDataStd_Name::Set(root, TCollection_ExtendedString(request.assembly.c_str(), true));
  std::vector<TDF_Label> groups;
  groups.reserve(request.groups.size());
  for (const std::string& name : request.groups) {
    groups.push_back(shapes->NewShape());
    TDataStd_Name::Set(groups.back(), TCollection_ExtendedString(name.c_str(), true));
  }
  std::vector<TDF_Label> labels;
  labels.reserve(request.shapes.size());
  for (const ShapeSpec& spec : request.shapes) {
    if (request.cancelled && request.cancelled()) {
      result.status = 3;
      return;
    }
    const TDF_Label label = shapes->AddShape(makeShape(spec), false);
    TDataStd_Name::Set(label, TCollection_ExtendedString(spec.name.c_str(), true));
    colors->SetColor(label,
                     Quantity_ColorRGBA(Quantity_Color(spec.color[0], spec.color[1], spec.color[2],
                                                       Quantity_TOC_RGB),
                                        spec.color[3]),
                     XCAFDoc_ColorSurf);
    // STEP keeps layers on shapes only (an instance cannot be on a layer).
    if (!spec.layer.empty())
      layers->SetLayer(label, TCollection_ExtendedString(spec.layer.c_str(), true));
    labels.push_back(label);
  }
  for (const Placement& placement : request.placements) {
    const TDF_Label parent = placement.group == ~0u ? root : groups.at(placement.group);
    const TDF_Label component = shapes->AddComponent(
        parent, labels.at(placement.shape), TopLoc_Location(transformOf(placement.matrix)));
    TDataStd_Name::Set(component, TCollection_ExtendedString(placement.name.c_str(), true));
  }
  for (std::size_t g = 0; g < groups.size(); ++g) {
    const TDF_Label component = shapes->AddComponent(root, groups[g], TopLoc_Location());
    TDataStd_Name::Set(component, TCollection_ExtendedString(request.groups[g].c_str(), true));
  }
  shapes->UpdateAssemblies();
  STEPCAFControl_Writer writer;
  writer.SetColorMode(true);
  writer.SetNameMode(true);
  writer.SetLayerMode(true);
  Interface_Static::SetCVal("write.step.schema", "AP214IS");
  Interface_Static::SetCVal("write.step.unit", "M");
  if (!writer.Transfer(doc, STEPControl_AsIs)) {
    result = {1, "OCCT could not transfer the assembly to STEP"};
  } else if (writer.Write(request.path.c_str()) != IFSelect_RetDone) {
    result = {1, "OCCT could not write the STEP file"};
  }
  XCAFApp_Application::GetApplication()->Close(doc);
}

}  // namespace
}  // namespace lodforge::cad

// No OCCT exception leaves the module.
extern "C" __attribute__((visibility("default"))) void lodforge_cad_write(
    int version, const lodforge::cad::WriteRequest& request, lodforge::cad::WriteResult& result) {
  result = {};
  if (version != lodforge::cad::kModuleVersion) {
    result = {1, fmt::format("the CAD module is version {}, lodforge wants {}",
                             lodforge::cad::kModuleVersion, version)};
    return;
  }
  static std::mutex writing;  // OCCT's writer statics are process-wide
  try {
    const std::lock_guard lock(writing);
    // OCCT's messages would go to stdout; the caller reports what matters.
    Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
    OCC_CATCH_SIGNALS
    lodforge::cad::write(request, result);
  } catch (const Standard_Failure& failure) {
    result = {1, fmt::format("OCCT failed: {} {}", failure.DynamicType()->Name(),
                             failure.GetMessageString())};
  } catch (const std::exception& failure) {
    result = {1, fmt::format("writing failed: {}", failure.what())};
  }
}
