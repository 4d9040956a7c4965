// The CAD reader against OpenCASCADE's own reading of the same files: part counts and names
// by an independent walk of the XDE tree, triangle counts by meshing the shape directly.
#include <gtest/gtest.h>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <IGESCAFControl_Writer.hxx>
#include <Quantity_Color.hxx>
#include <Quantity_ColorRGBA.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <STEPControl_Reader.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_LayerTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <gp_Pln.hxx>
#include <gp_Trsf.hxx>

#include <algorithm>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <map>
#include <set>

#include <fmt/format.h>

#include "lodforge/io/cad/cad_reader.h"
#include "lodforge/io/model_io.h"
#include "test_support.h"

namespace lodforge {
namespace {

const std::string kSamples = "/usr/share/opencascade/data";

std::string occtName(const TDF_Label& label) {
  Handle(TDataStd_Name) name;
  if (!label.FindAttribute(TDataStd_Name::GetID(), name)) return {};
  return TCollection_AsciiString(name->Get()).ToCString();
}

// OCCT's reading of a STEP file, walked with the shape tool (not the explorer the reader uses):
// the product name of every placed leaf, in tree order.
void leafNames(const TDF_Label& label, std::vector<std::string>& names) {
  TDF_Label shape = label;
  if (XCAFDoc_ShapeTool::IsReference(label)) XCAFDoc_ShapeTool::GetReferredShape(label, shape);
  if (!XCAFDoc_ShapeTool::IsAssembly(shape)) {
    names.push_back(occtName(shape));
    return;
  }
  TDF_LabelSequence components;
  XCAFDoc_ShapeTool::GetComponents(shape, components);
  for (const TDF_Label& c : components) leafNames(c, names);
}

std::vector<std::string> occtLeafNames(const std::string& path) {
  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  STEPCAFControl_Reader reader;
  reader.SetNameMode(true);
  EXPECT_EQ(reader.ReadFile(path.c_str()), IFSelect_RetDone);
  EXPECT_TRUE(reader.Transfer(doc));
  TDF_LabelSequence roots;
  XCAFDoc_DocumentTool::ShapeTool(doc->Main())->GetFreeShapes(roots);
  std::vector<std::string> names;
  for (const TDF_Label& root : roots) leafNames(root, names);
  XCAFApp_Application::GetApplication()->Close(doc);
  return names;
}

// Triangles OCCT makes of a shape at an absolute deflection.
std::uint64_t occtTriangles(const TopoDS_Shape& shape, double deflection, double angleDegrees) {
  BRepMesh_IncrementalMesh mesh(shape, deflection, false, angleDegrees * M_PI / 180, false);
  std::uint64_t triangles = 0;
  for (TopExp_Explorer face(shape, TopAbs_FACE); face.More(); face.Next()) {
    TopLoc_Location location;
    const Handle(Poly_Triangulation) t =
        BRep_Tool::Triangulation(TopoDS::Face(face.Current()), location);
    if (!t.IsNull()) triangles += static_cast<std::uint64_t>(t->NbTriangles());
  }
  return triangles;
}

TEST(CadRead, AStepAssemblyHasOcctsPartsAndNamesInMetres) {
  const std::string path = test::dataPath("cad/as1_motor.step");
  std::vector<std::string> warnings;
  CadReadStats stats;
  Result<Model> model = readCad(path, {}, &warnings, &stats);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_TRUE(warnings.empty()) << warnings.front();
  std::string why;
  EXPECT_TRUE(isConsistent(*model, &why)) << why;

  const std::vector<std::string> expected = occtLeafNames(path);
  ASSERT_EQ(model->objectCount(), expected.size());
  for (std::size_t o = 0; o < expected.size(); ++o)
    EXPECT_EQ(model->objectName(o), expected[o]) << o;
  EXPECT_EQ(stats.instances, expected.size());
  EXPECT_LT(stats.shapes, stats.instances) << "some parts are placed more than once";
  EXPECT_GE(stats.depth, 2u);

  // Every instance of one shape has its triangles (tessellated once, placed twice).
  std::map<std::string, std::pair<std::uint32_t, std::uint32_t>> counts;
  for (std::size_t o = 0; o < model->objectCount(); ++o) {
    const ObjectRecord& object = model->objects[o];
    EXPECT_GT(object.triangleCount, 0u) << model->objectName(o);
    const auto [at, added] = counts.try_emplace(std::string(model->objectName(o)),
                                                object.vertexCount, object.triangleCount);
    if (!added) {
      EXPECT_EQ(at->second, std::make_pair(object.vertexCount, object.triangleCount))
          << model->objectName(o);
    }
  }
  // Metres, as OCCT's own conversion of the file to glTF has it (meshes/as1_motor.glb, y up):
  // the file's coordinates are millimetres in the hundreds of thousands, a motor 209 m long.
  Result<Model> glb = readModel(test::dataPath("meshes/as1_motor.glb"));
  ASSERT_TRUE(glb.ok()) << glb.error().message;
  const Vec3f size = model->bounds().size(), glbSize = glb->bounds().size();
  EXPECT_NEAR(size.x, glbSize.x, 0.01 * glbSize.x);
  EXPECT_NEAR(size.y, glbSize.z, 0.01 * glbSize.z);
  EXPECT_NEAR(size.z, glbSize.y, 0.01 * glbSize.y);
  // Its parts carry colours, and not all the same one.
  ASSERT_TRUE(model->hasColors());
  EXPECT_NE(model->colors.front(), model->colors.back());
  ASSERT_TRUE(model->hasNormals());
  for (const Vec3f& n : model->normals) ASSERT_NEAR(length(n), 1.0f, 1e-4f);
}

TEST(CadRead, TrianglesAreOcctsAtTheSameDeflection) {
  struct Case {
    std::string path;
    double deflection;  // metres for STEP, the file's unit for BREP
  };
  for (const Case& c :
       {Case{kSamples + "/step/screw.step", 0.0002}, Case{kSamples + "/occ/Ball.brep", 0.05}}) {
    TopoDS_Shape shape;
    if (c.path.ends_with(".brep")) {
      BRep_Builder builder;
      ASSERT_TRUE(BRepTools::Read(shape, c.path.c_str(), builder));
    } else {
      STEPControl_Reader reader;
      ASSERT_EQ(reader.ReadFile(c.path.c_str()), IFSelect_RetDone);
      reader.TransferRoots();
      shape = reader.OneShape();
    }
    // OCCT reads STEP in millimetres by default.
    const double occtDeflection = c.path.ends_with(".brep") ? c.deflection : c.deflection * 1000;
    const std::uint64_t expected = occtTriangles(shape, occtDeflection, 20);
    CadReadOptions options;
    options.deflection = c.deflection;
    options.absoluteDeflection = true;
    Result<Model> model = readCad(c.path, options);
    ASSERT_TRUE(model.ok()) << model.error().message;
    EXPECT_GT(expected, 100u) << c.path;
    EXPECT_NEAR(static_cast<double>(model->triangleCount()), static_cast<double>(expected),
                0.02 * static_cast<double>(expected))
        << c.path;
    // A finer deflection makes more triangles.
    options.deflection /= 4;
    Result<Model> finer = readCad(c.path, options);
    ASSERT_TRUE(finer.ok());
    EXPECT_GT(finer->triangleCount(), model->triangleCount() * 3 / 2) << c.path;
  }
}

// (OCCT's larger IGES sample, bearing.iges, takes 8 s to mesh: the glTF validator's run converts
// it once, in the release tree.)
TEST(CadRead, IgesAndBrepSamplesRead) {
  for (const std::string name : {"iges/hammer.iges", "occ/Ball.brep"}) {
    Result<Model> model = readModel(kSamples + "/" + name);
    ASSERT_TRUE(model.ok()) << model.error().message;
    EXPECT_GT(model->triangleCount(), 500u) << name;
    std::string why;
    EXPECT_TRUE(isConsistent(*model, &why)) << name << ": " << why;
  }
  // A BREP file has no names; its part is named after the file.
  Result<Model> ball = readModel(kSamples + "/occ/Ball.brep");
  ASSERT_TRUE(ball.ok());
  EXPECT_EQ(ball->objectName(0), "Ball");
}

// A STEP file written by OCCT of the XDE document `fill` makes (shapes, names, colours).
void writeStep(const std::string& path,
               const std::function<void(XCAFDoc_ShapeTool&, XCAFDoc_ColorTool&)>& fill) {
  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  fill(*XCAFDoc_DocumentTool::ShapeTool(doc->Main()),
       *XCAFDoc_DocumentTool::ColorTool(doc->Main()));
  STEPCAFControl_Writer writer;
  ASSERT_TRUE(writer.Transfer(doc, STEPControl_AsIs));
  ASSERT_EQ(writer.Write(path.c_str()), IFSelect_RetDone);
  XCAFApp_Application::GetApplication()->Close(doc);
}

// A shape of the document under its name.
TDF_Label addNamed(XCAFDoc_ShapeTool& shapes, const TopoDS_Shape& shape,
                   const TCollection_ExtendedString& name) {
  const TDF_Label label = shapes.AddShape(shape, false);
  TDataStd_Name::Set(label, name);
  return label;
}

const Quantity_ColorRGBA kGlass(Quantity_Color(0.6, 0.8, 0.9, Quantity_TOC_sRGB), 0.12f);

// A STEP file of two coloured boxes named in Cyrillic, written by OCCT.
void writeCyrillicStep(const std::string& path) {
  writeStep(path, [](XCAFDoc_ShapeTool& shapes, XCAFDoc_ColorTool& colors) {
    const TDF_Label box = addNamed(shapes, BRepPrimAPI_MakeBox(10, 20, 30).Shape(),
                                   TCollection_ExtendedString("Корпус насоса", true));
    colors.SetColor(box, Quantity_Color(1, 0, 0, Quantity_TOC_sRGB), XCAFDoc_ColorSurf);
    addNamed(shapes, BRepPrimAPI_MakeBox(10, 20, 2).Shape(),
             TCollection_ExtendedString("Крышка", true));
  });
}

// The text with every Cyrillic letter (two-byte UTF-8, U+0410..U+044F) rewritten by `to`.
std::string recodeCyrillic(const std::string& text,
                           const std::function<std::string(unsigned)>& to) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if ((c == 0xD0 || c == 0xD1) && i + 1 < text.size()) {
      const unsigned code = ((c & 0x1Fu) << 6) | (static_cast<unsigned char>(text[i + 1]) & 0x3Fu);
      if (code >= 0x410 && code <= 0x44F) {
        out += to(code);
        ++i;
        continue;
      }
    }
    out.push_back(text[i]);
  }
  return out;
}

TEST(CadRead, CyrillicNamesArriveAsUtf8) {
  test::TempDir dir;
  const std::string utf8 = dir.file("pump.step");
  writeCyrillicStep(utf8);  // OCCT writes the names as UTF-8
  const std::string text = test::readFile(utf8);
  ASSERT_NE(text.find("Крышка"), std::string::npos);
  // The standard's escape: \X2\ and four hex digits of UTF-16 per letter, closed by \X0\ (one
  // escape per letter keeps the rewrite simple; readers take runs of any length).
  const std::string escaped = dir.file("pump-escaped.step");
  test::writeFile(escaped, recodeCyrillic(text, [](unsigned code) {
                    return fmt::format("\\X2\\{:04X}\\X0\\", code);
                  }));
  // Raw CP1251 bytes, as older Russian CAD systems write them (А..я are C0..FF).
  const std::string legacy = dir.file("pump-cp1251.step");
  test::writeFile(legacy, recodeCyrillic(text, [](unsigned code) {
                    return std::string(1, static_cast<char>(0xC0 + (code - 0x410)));
                  }));
  CadReadOptions cp1251;
  cp1251.codePage = "CP1251";
  for (const auto& [path, options] :
       {std::pair{utf8, CadReadOptions{}}, std::pair{escaped, CadReadOptions{}},
        std::pair{legacy, cp1251}}) {
    Result<Model> model = readCad(path, options);
    ASSERT_TRUE(model.ok()) << model.error().message;
    ASSERT_EQ(model->objectCount(), 2u) << path;
    EXPECT_EQ(model->objectName(0), "Корпус насоса") << path;
    EXPECT_EQ(model->objectName(1), "Крышка") << path;
    ASSERT_TRUE(model->hasColors()) << path;
    EXPECT_EQ(model->colors[model->objects[0].vertexOffset], (Rgba8{255, 0, 0, 255})) << path;
  }
  // Without the code page the legacy bytes are not UTF-8: their code page is guessed from them
  // (Cyrillic words are runs of high bytes), and a warning says so; UTF-8 given reads them as
  // UTF-8, garbled.
  std::vector<std::string> warnings;
  Result<Model> guessed = readCad(legacy, {}, &warnings);
  ASSERT_TRUE(guessed.ok()) << guessed.error().message;
  EXPECT_EQ(guessed->objectName(1), "Крышка");
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("read as CP1251, which their bytes suggest"), std::string::npos)
      << warnings[0];
  CadReadOptions utf8Given;
  utf8Given.codePage = "UTF8";
  Result<Model> unknown = readCad(legacy, utf8Given);
  ASSERT_TRUE(unknown.ok()) << unknown.error().message;
  EXPECT_NE(unknown->objectName(1), "Крышка");
}

// A STEP part with a translucent colour (STEP's surface_style_transparent, written by OCCT) keeps
// its alpha in its colours and gets a blended material; an opaque part gets none; and the tiles
// draw the glass with that material at every level.
TEST(CadRead, TranslucentPartsAreBlended) {
  test::TempDir dir;
  const std::string path = dir.file("window.step");
  writeStep(path, [](XCAFDoc_ShapeTool& shapes, XCAFDoc_ColorTool& colors) {
    const TDF_Label frame = addNamed(shapes, BRepPrimAPI_MakeBox(100, 10, 100).Shape(), "frame");
    colors.SetColor(frame, Quantity_Color(0.3, 0.3, 0.3, Quantity_TOC_sRGB), XCAFDoc_ColorSurf);
    colors.SetColor(
        addNamed(shapes, BRepPrimAPI_MakeBox(gp_Pnt(10, 2, 10), 80, 2, 80).Shape(), "glass"),
        kGlass, XCAFDoc_ColorSurf);
  });
  Result<Model> model = readCad(path);
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 2u);
  EXPECT_EQ(model->objectName(1), "glass");
  EXPECT_EQ(model->objects[0].material, kNoMaterial);
  ASSERT_LT(model->objects[1].material, model->materials.size());
  EXPECT_EQ(model->materials[model->objects[1].material].alphaMode, AlphaMode::kBlend);
  EXPECT_EQ(model->colors[model->objects[1].vertexOffset].a, 31);  // 0.12
  EXPECT_EQ(model->colors[model->objects[0].vertexOffset].a, 255);
}

// A part whose back faces can be seen (a face outside any shell, a shell with a free edge) gets a
// double-sided material, else a renderer culls its far side; a closed solid gets none, and a
// translucent sheet stays the translucent material, which is double-sided too.
TEST(CadRead, OpenShapesAreDoubleSided) {
  test::TempDir dir;
  const std::string path = dir.file("open.step");
  writeStep(path, [](XCAFDoc_ShapeTool& shapes, XCAFDoc_ColorTool& colors) {
    const auto sheet = [](double z) {
      return BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, z), gp_Dir(0, 0, 1)), 0, 10, 0, 10).Face();
    };
    addNamed(shapes, BRepPrimAPI_MakeBox(10, 10, 10).Shape(), "solid");
    addNamed(shapes, sheet(20), "sheet");
    // The box without its top face: one shell, four free edges.
    TopoDS_Shell lidless;
    BRep_Builder builder;
    builder.MakeShell(lidless);
    int faces = 0;
    for (TopExp_Explorer face(BRepPrimAPI_MakeBox(gp_Pnt(20, 0, 0), 10, 10, 10).Shape(),
                              TopAbs_FACE);
         face.More(); face.Next())
      if (++faces != 6) builder.Add(lidless, face.Current());
    addNamed(shapes, lidless, "lidless");
    colors.SetColor(addNamed(shapes, sheet(40), "glass"), kGlass, XCAFDoc_ColorSurf);
  });
  Result<Model> model = readCad(path);
  ASSERT_TRUE(model.ok()) << model.error().message;
  ASSERT_EQ(model->objectCount(), 4u);
  std::map<std::string, const Material*> materials;
  for (std::size_t o = 0; o < model->objectCount(); ++o) {
    const std::uint32_t m = model->objects[o].material;
    materials[std::string(model->objectName(o))] =
        m == kNoMaterial ? nullptr : &model->materials.at(m);
  }
  EXPECT_EQ(materials.at("solid"), nullptr);
  for (const char* open : {"sheet", "lidless"}) {
    ASSERT_NE(materials.at(open), nullptr) << open;
    EXPECT_TRUE(materials.at(open)->doubleSided) << open;
    EXPECT_EQ(materials.at(open)->alphaMode, AlphaMode::kOpaque) << open;
  }
  EXPECT_EQ(materials.at("sheet"), materials.at("lidless"));  // one material, listed once
  ASSERT_NE(materials.at("glass"), nullptr);
  EXPECT_EQ(materials.at("glass")->alphaMode, AlphaMode::kBlend);
  EXPECT_TRUE(materials.at("glass")->doubleSided);
}

// The names of an object's layers ("a; b" split), as a set: OCCT does not keep their order.
std::set<std::string> layerSet(std::string_view joined) {
  std::set<std::string> names;
  while (!joined.empty()) {
    const std::size_t end = std::min(joined.find("; "), joined.size());
    names.emplace(joined.substr(0, end));
    joined.remove_prefix(std::min(end + 2, joined.size()));
  }
  return names;
}

// Layers as CAD systems write them to STEP (on parts: an instance cannot be on one): every
// placed instance carries its part's layers, a part on two layers names both, a part on none
// has none, and each distinct set is listed once.
TEST(CadRead, LayersArriveOnEveryInstanceOfTheirParts) {
  test::TempDir dir;
  const std::string path = dir.file("layers.step");
  writeStep(path, [](XCAFDoc_ShapeTool& shapes, XCAFDoc_ColorTool&) {
    const TDF_Label frame = addNamed(shapes, BRepPrimAPI_MakeBox(10, 10, 10).Shape(), "frame");
    const TDF_Label cable =
        addNamed(shapes, BRepPrimAPI_MakeBox(gp_Pnt(20, 0, 0), 1, 1, 10).Shape(), "cable");
    addNamed(shapes, BRepPrimAPI_MakeBox(gp_Pnt(40, 0, 0), 5, 5, 5).Shape(), "loose");
    const TDF_Label bolt = addNamed(shapes, BRepPrimAPI_MakeBox(1, 1, 3).Shape(), "bolt");
    const TDF_Label fixing = shapes.NewShape();
    TDataStd_Name::Set(fixing, "fixing");
    for (double x : {0.0, 5.0}) {
      gp_Trsf at;
      at.SetTranslation(gp_Vec(x, 0, 12));
      shapes.AddComponent(fixing, bolt, TopLoc_Location(at));
    }
    shapes.UpdateAssemblies();
    const Handle(XCAFDoc_LayerTool) layers = XCAFDoc_DocumentTool::LayerTool(frame);
    layers->SetLayer(frame, "structure");
    layers->SetLayer(cable, "electrical");
    layers->SetLayer(cable, "harness");
    layers->SetLayer(bolt, "fasteners");
  });
  Result<Model> model = readCad(path);
  ASSERT_TRUE(model.ok()) << model.error().message;
  std::map<std::string, std::vector<std::set<std::string>>> layersByName;
  for (std::size_t o = 0; o < model->objectCount(); ++o)
    layersByName[std::string(model->objectName(o))].push_back(layerSet(model->objectLayer(o)));
  using Sets = std::vector<std::set<std::string>>;
  EXPECT_EQ(layersByName.at("frame"), (Sets{{"structure"}}));
  EXPECT_EQ(layersByName.at("cable"), (Sets{{"electrical", "harness"}}));
  EXPECT_EQ(layersByName.at("loose"), (Sets{{}}));
  EXPECT_EQ(layersByName.at("bolt"), (Sets{{"fasteners"}, {"fasteners"}}));
  EXPECT_EQ(model->layers.size(), 3u);  // structure, the cable's pair, fasteners
  EXPECT_EQ(std::set<std::string>(model->layers.begin(), model->layers.end()).size(),
            model->layers.size());
}

// The names of the model's objects, sorted.
std::vector<std::string> sortedNames(const Model& model) {
  std::vector<std::string> names;
  for (std::size_t o = 0; o < model.objectCount(); ++o) names.emplace_back(model.objectName(o));
  std::sort(names.begin(), names.end());
  return names;
}

// Parts a CAD system hides, as OCCT writes them to STEP (INVISIBILITY of a product, and of a
// layer's assignment): left out by default with a warning that counts them, kept with `hidden`;
// a visible layer hides nothing; a file that hides every part is bad input that says what works.
TEST(CadRead, HiddenPartsAreLeftOutUnlessKept) {
  test::TempDir dir;
  const std::string path = dir.file("hidden.step");
  writeStep(path, [](XCAFDoc_ShapeTool& shapes, XCAFDoc_ColorTool& colors) {
    const TDF_Label shown = addNamed(shapes, BRepPrimAPI_MakeBox(1, 1, 1).Shape(), "shown");
    const TDF_Label ghost =
        addNamed(shapes, BRepPrimAPI_MakeBox(gp_Pnt(2, 0, 0), 1, 1, 1).Shape(), "ghost");
    const TDF_Label scaffold =
        addNamed(shapes, BRepPrimAPI_MakeBox(gp_Pnt(4, 0, 0), 1, 1, 1).Shape(), "scaffold");
    colors.SetVisibility(ghost, false);
    const Handle(XCAFDoc_LayerTool) layers = XCAFDoc_DocumentTool::LayerTool(shown);
    layers->SetLayer(shown, "main");
    layers->SetLayer(scaffold, "construction");
    TDF_Label construction;
    ASSERT_TRUE(layers->FindLayer("construction", construction));
    layers->SetVisibility(construction, false);
  });
  std::vector<std::string> warnings;
  CadReadStats stats;
  Result<Model> model = readCad(path, {}, &warnings, &stats);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(sortedNames(*model), (std::vector<std::string>{"shown"}));
  EXPECT_EQ(stats.hidden, 2u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ(warnings[0], path + ": 2 part(s) the file hides left out (--hidden keeps them)");

  CadReadOptions keep;
  keep.hidden = true;
  warnings.clear();
  model = readCad(path, keep, &warnings, &stats);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(sortedNames(*model), (std::vector<std::string>{"ghost", "scaffold", "shown"}));
  EXPECT_EQ(stats.hidden, 0u);
  EXPECT_TRUE(warnings.empty());

  const std::string allHidden = dir.file("all-hidden.step");
  writeStep(allHidden, [](XCAFDoc_ShapeTool& shapes, XCAFDoc_ColorTool& colors) {
    colors.SetVisibility(addNamed(shapes, BRepPrimAPI_MakeBox(1, 1, 1).Shape(), "ghost"), false);
  });
  Result<Model> none = readCad(allHidden);
  ASSERT_FALSE(none.ok());
  EXPECT_EQ(none.error().kind, ErrorKind::kBadInput);
  EXPECT_EQ(none.error().message,
            allHidden + ": the file hides every part in it (--hidden keeps them)");
  EXPECT_TRUE(readCad(allHidden, keep).ok());
}

// IGES hides an entity by its blank status (columns 65-66 of its directory entry's first line),
// which OCCT's reader does not carry; the reader marks a blanked root's shape hidden itself. The
// file is written by OCCT (three parts, each a root 402 group) and the second root blanked.
TEST(CadRead, BlankedIgesRootsAreHidden) {
  test::TempDir dir;
  const std::string path = dir.file("blanked.igs");
  {
    Handle(TDocStd_Document) doc;
    XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
    XCAFDoc_ShapeTool& shapes = *XCAFDoc_DocumentTool::ShapeTool(doc->Main());
    addNamed(shapes, BRepPrimAPI_MakeBox(1, 1, 1).Shape(), "shown");
    addNamed(shapes, BRepPrimAPI_MakeBox(gp_Pnt(2, 0, 0), 1, 1, 1).Shape(), "blanked");
    addNamed(shapes, BRepPrimAPI_MakeBox(gp_Pnt(4, 0, 0), 1, 1, 1).Shape(), "also shown");
    IGESCAFControl_Writer writer;
    ASSERT_TRUE(writer.Transfer(doc));
    ASSERT_TRUE(writer.Write(path.c_str()));
    XCAFApp_Application::GetApplication()->Close(doc);
  }
  std::string text = test::readFile(path);
  std::vector<std::size_t> roots;  // the first line of each independent 402's directory entry
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::string_view line(text.data() + at, end - at);
    if (line.size() >= 80 && line[72] == 'D' && (line[79] - '0') % 2 == 1 &&
        line.substr(0, 8) == "     402" && line.substr(66, 2) == "00")
      roots.push_back(at);
    at = end + 1;
  }
  ASSERT_EQ(roots.size(), 3u);
  ASSERT_EQ(text.substr(roots[1] + 64, 2), "00");
  text.replace(roots[1] + 64, 2, "01");
  test::writeFile(path, text);

  CadReadStats stats;
  Result<Model> model = readCad(path, {}, nullptr, &stats);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(sortedNames(*model), (std::vector<std::string>{"also shown", "shown"}));
  EXPECT_EQ(stats.hidden, 1u);
  CadReadOptions keep;
  keep.hidden = true;
  model = readCad(path, keep, nullptr, &stats);
  ASSERT_TRUE(model.ok()) << model.error().message;
  EXPECT_EQ(sortedNames(*model), (std::vector<std::string>{"also shown", "blanked", "shown"}));
}

TEST(CadRead, BadFilesAreBadInputNamingTheFile) {
  test::TempDir dir;
  const std::string screw = test::readFile(kSamples + "/step/screw.step");
  struct Case {
    std::string name, contents;
  };
  for (const Case& c : {
           Case{"empty.step", ""},
           Case{"garbage.step", "this is not STEP\n\x01\x02\x03"},
           Case{"truncated.step", screw.substr(0, screw.size() / 2)},
           Case{"no-shapes.step",
                "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\nFILE_NAME('x','',(''),"
                "(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\nENDSEC;\n"
                "END-ISO-10303-21;\n"},
           Case{"garbage.iges", "not IGES at all\n"},
           Case{"garbage.brep", "DBRep_DrawableShape\ngarbage\n"},
       }) {
    const std::string path = dir.file(c.name);
    test::writeFile(path, c.contents);
    Result<Model> model = readCad(path);
    ASSERT_FALSE(model.ok()) << c.name;
    EXPECT_EQ(model.error().kind, ErrorKind::kBadInput) << c.name << ": " << model.error().message;
    EXPECT_EQ(model.error().message.rfind(path + ": ", 0), 0u) << model.error().message;
  }
  // An IGES file whose face has no surface (found by fuzz_cad) crashed inside OCCT's transfer
  // (a null dereference in IGESSolid_Face::Surface); OCCT's signal conversion makes it a failure
  // OCCT's transfer catches per entity, and the rest of the file is read.
  const std::string nullSurface = test::testDataPath("cad/null-surface.iges");
  Result<Model> survived = readCad(nullSurface);
  if (!survived.ok()) {
    EXPECT_EQ(survived.error().kind, ErrorKind::kBadInput) << survived.error().message;
  } else {
    std::string why;
    EXPECT_TRUE(isConsistent(*survived, &why)) << why;
  }
  // Bad options are usage errors.
  CadReadOptions options;
  options.codePage = "KOI9";
  Result<Model> model = readCad(kSamples + "/step/screw.step", options);
  ASSERT_FALSE(model.ok());
  EXPECT_EQ(model.error().kind, ErrorKind::kUsage) << model.error().message;
  options = {};
  options.deflection = 0;
  EXPECT_EQ(readCad(kSamples + "/step/screw.step", options).error().kind, ErrorKind::kUsage);
}

// A BREP location raised to the power 50,000,000 (found by fuzz_cad): OCCT's
// TopLoc_Location::Powered recurses once per power and overflows the stack. OCCT's handler runs on
// an alternate signal stack, so the read fails as bad input and the process goes on; std::cout,
// which the BREP read redirects, gets its own buffer back (a dangling one crashed at exit).
TEST(CadRead, AStackOverflowInsideOcctIsBadInput) {
  std::streambuf* const out = std::cout.rdbuf();
  const std::string powered = test::testDataPath("cad/powered-location.brep");
  for (int attempt = 0; attempt < 2; ++attempt) {
    Result<Model> overflowed = readCad(powered);
    ASSERT_FALSE(overflowed.ok());
    EXPECT_EQ(overflowed.error().kind, ErrorKind::kBadInput) << overflowed.error().message;
    EXPECT_EQ(overflowed.error().message.rfind(powered + ": OCCT crashed", 0), 0u)
        << overflowed.error().message;
  }
  EXPECT_EQ(std::cout.rdbuf(), out);
  Result<Model> box = readCad(kSamples + "/step/screw.step");
  EXPECT_TRUE(box.ok()) << box.error().message;
}

// A place for the module that cannot be looked at ($LODFORGE_CAD_MODULE too long a name for the
// system) is passed over, not an exception out of the reader: the module loads from the next
// place. In a fresh process (the threadsafe style runs the test again), where nothing has loaded
// the module yet.
TEST(CadReadDeathTest, AModulePlaceThatCannotBeLookedAtIsPassedOver) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(
      {
        const std::string tooLong = "/tmp/" + std::string(300, 'x') + "/liblodforge_cad.so";
        ::setenv("LODFORGE_CAD_MODULE", tooLong.c_str(), 1);
        Result<Model> screw = readCad(kSamples + "/step/screw.step");
        if (!screw.ok()) std::cerr << screw.error().message << '\n';
        std::exit(screw.ok() ? 0 : 1);
      },
      ::testing::ExitedWithCode(0), "");
}

}  // namespace
}  // namespace lodforge
