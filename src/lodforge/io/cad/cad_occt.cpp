// The OpenCASCADE module (liblodforge_cad.so, see cad_module.h): a STEP, IGES or BREP file read
// into an XDE document, its distinct shapes tessellated once each, every placed instance's
// triangles written out in plain arrays. Loaded by cad_reader.cpp only when a CAD file is read.
#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <BRepBndLib.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IMeshTools_Parameters.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_InterfaceModel.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <Message_PrinterOStream.hxx>
#include <Message_ProgressIndicator.hxx>
#include <Message_ProgressScope.hxx>
#include <OSD.hxx>
#include <OSD_Signal.hxx>
#include <RWMesh_FaceIterator.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPControl_Controller.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TDF_LabelSequence.hxx>
#include <TDF_Tool.hxx>
#include <TDataStd_Name.hxx>
#include <TDocStd_Document.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TransferBRep.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_ColorTool.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_LayerTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <XCAFDoc_VisMaterial.hxx>
#include <XCAFPrs_DocumentExplorer.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <vector>

#include "lodforge/io/cad/cad_module.h"

namespace lodforge::cad {
namespace {

enum class CadFormat : std::uint8_t { kNone, kStep, kIges, kBrep };

// Lower-case extension without the dot.
std::string extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  if (!ext.empty()) ext.erase(0, 1);
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

CadFormat cadFormat(const std::string& path) {
  const std::string ext = extension(path);
  if (ext == "step" || ext == "stp") return CadFormat::kStep;
  if (ext == "iges" || ext == "igs") return CadFormat::kIges;
  if (ext == "brep" || ext == "brp") return CadFormat::kBrep;
  return CadFormat::kNone;
}

// OCCT reports through its default messenger, which prints to stdout. One printer that keeps
// the failures (and the warnings, for a reader that fails without a failure) replaces it; the
// readers run one at a time (their statics are shared), so it is read after each.
class KeptMessages : public Message_Printer {
 public:
  std::vector<std::string> take() {
    std::lock_guard lock(mutex_);
    return std::exchange(kept_, {});
  }

 protected:
  void send(const TCollection_AsciiString& text, const Message_Gravity gravity) const override {
    if (gravity < Message_Warning) return;
    std::lock_guard lock(mutex_);
    if (kept_.size() < 20) kept_.emplace_back(text.ToCString());
  }

 private:
  mutable std::mutex mutex_;
  mutable std::vector<std::string> kept_;
};

struct Occt {
  std::mutex reading;  // OCCT's reader statics are process-wide
  Handle(KeptMessages) messages = new KeptMessages;
  Occt() {
    const Handle(Message_Messenger)& messenger = Message::DefaultMessenger();
    messenger->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
    messenger->AddPrinter(messages);
    STEPControl_Controller::Init();
    IGESControl_Controller::Init();
  }
};

Occt& occt() {
  static Occt instance;
  return instance;
}

std::string utf8(const TCollection_ExtendedString& text) {
  std::string out(static_cast<std::size_t>(text.LengthOfCString()), '\0');
  Standard_PCharacter at = out.data();
  out.resize(static_cast<std::size_t>(text.ToUTF8CString(at)));
  return out;
}

std::string labelName(const TDF_Label& label) {
  Handle(TDataStd_Name) name;
  if (label.IsNull() || !label.FindAttribute(TDataStd_Name::GetID(), name)) return {};
  return utf8(name->Get());
}

std::string reason(std::vector<std::string> messages, std::string_view fallback) {
  if (messages.empty()) return std::string(fallback);
  for (std::string& m : messages) std::replace(m.begin(), m.end(), '\n', ' ');
  return fmt::format("{} (OCCT: {})", fallback, fmt::join(messages, "; "));
}

// OCCT's signal handlers for the length of one read: a crash inside OCCT (a null surface in a
// damaged IGES file, found by fuzz_cad) jumps to the nearest `guarded` and becomes a
// Standard_Failure instead of ending the process. Ctrl-C and termination keep lodforge's
// handlers; every handler is put back afterwards.
class OcctSignals {
 public:
  OcctSignals() {
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], nullptr, &saved_[i]);
    OSD::SetSignal(OSD_SignalMode_Set, false);
    for (std::size_t i = 0; i < kSignals.size(); ++i) {
      if (!isCrash(kSignals[i])) {
        sigaction(kSignals[i], &saved_[i], nullptr);
        continue;
      }
      // OCCT's handler runs on the thread's alternate stack (SignalStack), so a stack overflow
      // inside OCCT reaches it too.
      struct sigaction occt {};
      sigaction(kSignals[i], nullptr, &occt);
      occt.sa_flags |= SA_ONSTACK;
      sigaction(kSignals[i], &occt, nullptr);
    }
  }
  ~OcctSignals() {
    for (std::size_t i = 0; i < kSignals.size(); ++i) sigaction(kSignals[i], &saved_[i], nullptr);
  }
  OcctSignals(const OcctSignals&) = delete;
  OcctSignals& operator=(const OcctSignals&) = delete;

 private:
  static constexpr std::array<int, 9> kSignals = {SIGSEGV, SIGBUS,  SIGFPE, SIGILL, SIGSYS,
                                                  SIGINT,  SIGTERM, SIGHUP, SIGQUIT};
  static bool isCrash(int signal) {
    return signal == SIGSEGV || signal == SIGBUS || signal == SIGFPE || signal == SIGILL ||
           signal == SIGSYS;
  }
  std::array<struct sigaction, kSignals.size()> saved_{};
};

// An alternate signal stack for this thread while it runs OCCT: a stack overflow inside OCCT
// (TopLoc_Location::Powered recurses once per power, and a damaged BREP location can ask for
// 50 million, found by fuzz_cad) leaves no stack for the handler on the thread's own. The stack
// the thread had before (ASan's, for one) is put back afterwards.
class SignalStack {
 public:
  SignalStack() {
    thread_local std::vector<char> memory(std::size_t{256} << 10);
    stack_t mine{};
    mine.ss_sp = memory.data();
    mine.ss_size = memory.size();
    sigaltstack(&mine, &saved_);
  }
  ~SignalStack() { sigaltstack(&saved_, nullptr); }
  SignalStack(const SignalStack&) = delete;
  SignalStack& operator=(const SignalStack&) = delete;

 private:
  stack_t saved_{};
};

// Runs `work` where a signal inside OCCT is thrown as a Standard_Failure (OCC_CATCH_SIGNALS).
// The signal jumps here past the frames in between, whose destructors do not run.
template <class Work>
void guarded(Work&& work) {
  const SignalStack stack;
  OCC_CATCH_SIGNALS
  work();
}

// A failure of the read, carried to the entry point: bad input (1) or a bad option (2).
struct Failure {
  int status = 1;
  std::string message;
};

Failure badFile(std::string_view what) {
  return {1, reason(occt().messages->take(), what)};
}

// The entities of `checks` that failed, as "#N: OCCT's first reason", appended to `lost` (a
// check on the whole file is "file"); one entity once.
void keepFails(const Interface_CheckIterator& checks,
               const Handle(Interface_InterfaceModel) & model, std::vector<std::string>& lost) {
  for (checks.Start(); checks.More(); checks.Next()) {
    const Handle(Interface_Check)& check = checks.Value();
    if (check.IsNull() || check->NbFails() == 0) continue;
    std::string label = checks.Number() == 0 ? "file" : fmt::format("entity {}", checks.Number());
    if (!model.IsNull() && check->HasEntity())
      if (const Handle(TCollection_HAsciiString) name = model->StringLabel(check->Entity());
          !name.IsNull())
        label = name->ToCString();
    std::string line = fmt::format("{}: {}", label, check->CFail(1));
    if (std::find(lost.begin(), lost.end(), line) == lost.end()) lost.push_back(std::move(line));
  }
}

XSControl_WorkSession& session(STEPCAFControl_Reader& reader) {
  return *reader.ChangeReader().WS();
}
XSControl_WorkSession& session(IGESCAFControl_Reader& reader) {
  return *reader.WS();
}

// One XDE reader (STEP's or IGES's) over the file into `doc`, lengths in metres; what OCCT
// failed to read or transfer goes to `lost`.
template <class Reader>
std::optional<Failure> transfer(Reader& reader, const std::string& path, std::string_view format,
                                Handle(TDocStd_Document) & doc, std::vector<std::string>& lost) {
  reader.SetColorMode(true);
  reader.SetNameMode(true);
  reader.SetLayerMode(true);
  if (reader.ReadFile(path.c_str()) != IFSelect_RetDone)
    return badFile(fmt::format("not {} file OCCT can read", format));
  XSControl_WorkSession& work = session(reader);
  keepFails(work.ModelCheckList(), work.Model(), lost);
  if (reader.NbRootsForTransfer() == 0)
    return badFile(fmt::format("{} file with no shape in it", format));
  XCAFDoc_DocumentTool::SetLengthUnit(doc, 1.0);  // shapes in metres
  if (!reader.Transfer(doc)) return badFile("OCCT could not transfer its shapes");
  if (const Handle(XSControl_TransferReader) transferred = work.TransferReader();
      !transferred.IsNull() && !transferred->TransientProcess().IsNull())
    keepFails(transferred->TransientProcess()->CheckList(true), work.Model(), lost);
  return {};
}

// IGES keeps visibility in each entity's blank status, which OCCT's reader does not carry into
// the document: the shape of a blanked root entity is marked invisible here, as STEP's
// INVISIBILITY is by OCCT, so walkTree treats both alike.
void hideBlankedRoots(IGESCAFControl_Reader& reader, const Handle(TDocStd_Document) & doc) {
  const Handle(XSControl_WorkSession) session = reader.WS();
  const Handle(Interface_InterfaceModel) model = session->Model();
  const Handle(Transfer_TransientProcess) process = session->TransferReader()->TransientProcess();
  if (model.IsNull() || process.IsNull()) return;
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  const Handle(XCAFDoc_ColorTool) colors = XCAFDoc_DocumentTool::ColorTool(doc->Main());
  for (Standard_Integer i = 1; i <= model->NbEntities(); ++i) {
    const Handle(IGESData_IGESEntity) entity =
        Handle(IGESData_IGESEntity)::DownCast(model->Value(i));
    if (entity.IsNull() || entity->BlankStatus() != 1 || entity->SubordinateStatus() != 0) continue;
    const TopoDS_Shape shape = TransferBRep::ShapeResult(process, entity);
    TDF_Label label;
    // The root's own label (each transferred root is a shape of the document), not a subshape.
    if (!shape.IsNull() && shapes->Search(shape, label, true, true, false))
      colors->SetVisibility(label, false);
  }
}

// The STEP or IGES file into `doc`; a failure's message, or nothing.
std::optional<Failure> readStepOrIges(const std::string& path, CadFormat format,
                                      const Request& request, Handle(TDocStd_Document) & doc,
                                      std::vector<std::string>& lost) {
  if (format == CadFormat::kIges) {
    IGESCAFControl_Reader reader;
    std::optional<Failure> failed = transfer(reader, path, "an IGES", doc, lost);
    if (!failed) hideBlankedRoots(reader, doc);
    return failed;
  }
  const std::string page = request.codePage.empty() ? "UTF8" : request.codePage;
  if (!Interface_Static::SetCVal("read.step.codepage", page.c_str()))
    return Failure{2, fmt::format("--code-page {}: not a code page OCCT knows (e.g. UTF8, "
                                  "CP1251, CP1252, SJIS, GB)",
                                  page)};
  STEPCAFControl_Reader reader;
  return transfer(reader, path, "a STEP", doc, lost);
}

std::optional<Failure> readBrep(const std::string& path, Handle(TDocStd_Document) & doc) {
  TopoDS_Shape shape;
  BRep_Builder builder;
  // BRepTools reports on std::cout, not through the messenger: kept for the error instead. A
  // crash inside the read jumps to the nearest `guarded`, so that one is here, where std::cout's
  // own buffer is put back.
  std::ostringstream said;
  std::streambuf* const out = std::cout.rdbuf(said.rdbuf());
  bool read = false;
  try {
    guarded([&] { read = BRepTools::Read(shape, path.c_str(), builder); });
  } catch (...) {
    std::cout.rdbuf(out);
    throw;
  }
  std::cout.rdbuf(out);
  if (!read || shape.IsNull()) {
    std::string why = said.str();
    while (!why.empty() && std::isspace(static_cast<unsigned char>(why.back()))) why.pop_back();
    std::replace(why.begin(), why.end(), '\n', ' ');
    return why.empty() ? badFile("not a BREP file OCCT can read")
                       : Failure{1, fmt::format("not a BREP file OCCT can read (OCCT: {})", why)};
  }
  const Handle(XCAFDoc_ShapeTool) shapes = XCAFDoc_DocumentTool::ShapeTool(doc->Main());
  const TDF_Label label = shapes->AddShape(shape, false);
  TDataStd_Name::Set(
      label, TCollection_ExtendedString(std::filesystem::path(path).stem().string().c_str(), true));
  return {};
}

// The file into an XDE document (assembly tree, names, colours, layers).
std::optional<Failure> readDocument(const Request& request, Handle(TDocStd_Document) & doc,
                                    std::vector<std::string>& lost) {
  const CadFormat format = cadFormat(request.path);
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  occt().messages->take();
  std::optional<Failure> failed = format == CadFormat::kBrep
                                      ? readBrep(request.path, doc)
                                      : readStepOrIges(request.path, format, request, doc, lost);
  if (failed) return failed;
  TDF_LabelSequence roots;
  XCAFDoc_DocumentTool::ShapeTool(doc->Main())->GetFreeShapes(roots);
  if (roots.IsEmpty()) return Failure{1, "no shape in the file"};
  return {};
}

// A placed leaf of the assembly: which shape, where, in what style, under which name.
struct Placed {
  std::size_t shape;  // into the distinct shapes
  TDF_Label label;    // the shape's label (its product)
  TopLoc_Location location;
  XCAFPrs_Style style;
  std::string name;
  std::string path;   // the names from the root down to this leaf, "/"-separated
  std::string layer;  // its layers, "; "-separated
};

struct Tree {
  std::vector<TDF_Label> shapes;  // distinct, in first-placed order
  std::vector<Placed> placed;
  std::uint32_t depth = 0;
  std::uint64_t hidden = 0;  // leaves left out because the file hides them
};

// The layers of a placed leaf, each once: its instance's and its part's (STEP keeps layers on
// parts; IGES levels sit on either).
std::string layersOf(const Handle(XCAFDoc_LayerTool) & tool, const XCAFPrs_DocumentNode& node) {
  std::vector<std::string> names;
  for (const TDF_Label& label : {node.Label, node.RefLabel}) {
    Handle(TColStd_HSequenceOfExtendedString) found;
    if (label.IsNull() || !tool->GetLayers(label, found) || found.IsNull()) continue;
    for (Standard_Integer i = 1; i <= found->Length(); ++i) {
      std::string name = utf8(found->Value(i));
      if (!name.empty() && std::find(names.begin(), names.end(), name) == names.end())
        names.push_back(std::move(name));
    }
  }
  std::string joined;
  for (const std::string& name : names) joined += (joined.empty() ? "" : "; ") + name;
  return joined;
}

// Whether the file hides the explorer's leaf: a product or instance on its path marked
// invisible (STEP's INVISIBILITY, XCAFDoc_ColorTool::IsVisible), or the leaf on a hidden layer.
// A layer hides what is on it, so one hidden layer of several is enough.
bool isHidden(const XCAFPrs_DocumentExplorer& it, const Handle(XCAFDoc_ColorTool) & colors,
              const Handle(XCAFDoc_LayerTool) & layers) {
  for (int depth = 0; depth <= it.CurrentDepth(); ++depth) {
    const XCAFPrs_DocumentNode& node = it.Current(depth);
    for (const TDF_Label& label : {node.Label, node.RefLabel})
      if (!label.IsNull() && !colors->IsVisible(label)) return true;
  }
  for (const TDF_Label& label : {it.Current().Label, it.Current().RefLabel}) {
    TDF_LabelSequence on;
    if (label.IsNull() || !layers->GetLayers(label, on)) continue;
    for (Standard_Integer i = 1; i <= on.Length(); ++i)
      if (!layers->IsVisible(on.Value(i))) return true;
  }
  return false;
}

// The leaves in the order the tree lists them; a shape placed again refers to its first entry.
// Leaves the file hides are counted and left out, unless `keepHidden`.
Tree walkTree(const Handle(TDocStd_Document) & doc, bool keepHidden) {
  Tree tree;
  std::map<std::string, std::size_t> seen;  // label entry → shape
  const Handle(XCAFDoc_LayerTool) layers = XCAFDoc_DocumentTool::LayerTool(doc->Main());
  const Handle(XCAFDoc_ColorTool) colors = XCAFDoc_DocumentTool::ColorTool(doc->Main());
  for (XCAFPrs_DocumentExplorer it(doc, XCAFPrs_DocumentExplorerFlags_OnlyLeafNodes); it.More();
       it.Next()) {
    if (!keepHidden && isHidden(it, colors, layers)) {
      ++tree.hidden;
      continue;
    }
    const XCAFPrs_DocumentNode& node = it.Current();
    TCollection_AsciiString entry;
    TDF_Tool::Entry(node.RefLabel, entry);
    const auto [at, added] = seen.try_emplace(entry.ToCString(), tree.shapes.size());
    if (added) tree.shapes.push_back(node.RefLabel);
    const auto nameOf = [](const XCAFPrs_DocumentNode& n) {
      std::string name = labelName(n.RefLabel);
      return name.empty() ? labelName(n.Label) : name;
    };
    std::string path;
    for (int depth = 0; depth <= it.CurrentDepth(); ++depth)
      path += (depth > 0 ? "/" : "") + nameOf(it.Current(depth));
    tree.placed.push_back({at->second, node.RefLabel, node.Location, node.Style, nameOf(node),
                           std::move(path), layersOf(layers, node)});
    tree.depth = std::max(tree.depth, static_cast<std::uint32_t>(it.CurrentDepth() + 1));
  }
  return tree;
}

// The chord error for one shape, in the document's unit.
double deflectionOf(const TopoDS_Shape& shape, const Request& request, double metresPerUnit) {
  if (request.absoluteDeflection) return request.deflection / metresPerUnit;
  Bnd_Box box;
  BRepBndLib::Add(shape, box);
  const double diagonal = box.IsVoid() ? 1.0 : std::sqrt(box.SquareExtent());
  return std::max(request.deflection * diagonal, 1e-9);
}

// OCCT's mesher asks its progress indicator whether to stop: the caller's cancellation.
class Cancellation : public Message_ProgressIndicator {
 public:
  explicit Cancellation(bool (*cancelled)()) : cancelled_(cancelled) {}
  Standard_Boolean UserBreak() override { return cancelled_ && cancelled_(); }
  void Show(const Message_ProgressScope&, const Standard_Boolean) override {}

 private:
  bool (*cancelled_)();
};

bool isCancelled(const Request& request) {
  return request.cancelled && request.cancelled();
}

// Each distinct shape tessellated once, in parallel; a shape OCCT fails on gets the reason.
std::vector<std::string> tessellate(const Tree& tree, const Request& request,
                                    double metresPerUnit) {
  std::vector<std::string> failures(tree.shapes.size());
  const double angle = request.angleDegrees * M_PI / 180;
  if (request.shapes) request.shapes(request.context, tree.shapes.size());
  tbb::parallel_for(std::size_t{0}, tree.shapes.size(), [&](std::size_t s) {
    if (isCancelled(request)) return;
    const TopoDS_Shape shape = XCAFDoc_ShapeTool::GetShape(tree.shapes[s]);
    try {
      IMeshTools_Parameters parameters;
      parameters.Deflection = deflectionOf(shape, request, metresPerUnit);
      parameters.Angle = angle;
      const Handle(Cancellation) cancellation = new Cancellation(request.cancelled);
      guarded([&] {
        BRepMesh_IncrementalMesh mesh(shape, parameters, cancellation->Start());
        if (!mesh.IsDone() && !isCancelled(request)) failures[s] = "OCCT's mesher did not finish";
      });
      if (request.meshed) request.meshed(request.context);
    } catch (const Standard_Failure& failure) {
      failures[s] = fmt::format("OCCT's mesher failed: {} {}", failure.DynamicType()->Name(),
                                failure.GetMessageString());
    } catch (const std::exception& failure) {
      failures[s] = fmt::format("the mesher failed: {}", failure.what());
    }
  });
  return failures;
}

// Whether a shape shows its back faces: some face lies outside a shell, or a shell has free
// edges (a sheet, a surface model). Such a part needs doubleSided or its far side vanishes.
bool isOpen(const TopoDS_Shape& shape) {
  if (TopExp_Explorer(shape, TopAbs_FACE, TopAbs_SHELL).More()) return true;
  for (TopExp_Explorer shell(shape, TopAbs_SHELL); shell.More(); shell.Next())
    if (!BRep_Tool::IsClosed(shell.Current())) return true;
  return false;
}

std::vector<char> openShapes(const Tree& tree) {
  std::vector<char> open(tree.shapes.size());
  for (std::size_t s = 0; s < tree.shapes.size(); ++s)
    open[s] = isOpen(XCAFDoc_ShapeTool::GetShape(tree.shapes[s]));
  return open;
}

std::uint32_t facesWithoutTriangles(const TopoDS_Shape& shape) {
  std::uint32_t missing = 0;
  for (TopExp_Explorer face(shape, TopAbs_FACE); face.More(); face.Next()) {
    TopLoc_Location location;
    if (BRep_Tool::Triangulation(TopoDS::Face(face.Current()), location).IsNull()) ++missing;
  }
  return missing;
}

void pushColor(const Quantity_ColorRGBA& color, std::vector<std::uint8_t>& out) {
  const auto byte = [](double v) {
    return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
  };
  // OCCT keeps colours linear; vertex colours are sRGB bytes like every other reader's.
  Standard_Real r = 0, g = 0, b = 0;
  color.GetRGB().Values(r, g, b, Quantity_TOC_sRGB);
  out.insert(out.end(), {byte(r), byte(g), byte(b), byte(color.Alpha())});
}

// The instance's material: OCCT's visual material (PBR, or common converted to PBR) when the
// part has one; else, for a part with a translucent face (STEP's surface transparency), a
// blended "translucent" material; else, for an open shape, a "double-sided" one; else none.
// Equal materials are listed once.
std::uint32_t materialOf(const XCAFPrs_Style& style, bool translucent, bool open, Result& out) {
  Material material;
  const Handle(XCAFDoc_VisMaterial)& vis = style.Material();
  if (!vis.IsNull() && !vis->IsEmpty()) {
    const XCAFDoc_VisMaterialPBR pbr = vis->ConvertToPbrMaterial();
    material.name = vis->RawName().IsNull()
                        ? ""
                        : utf8(TCollection_ExtendedString(vis->RawName()->ToCString(), true));
    Standard_Real r = 1, g = 1, b = 1;
    pbr.BaseColor.GetRGB().Values(r, g, b, Quantity_TOC_RGB);  // linear, as glTF's
    const float base[4] = {static_cast<float>(r), static_cast<float>(g), static_cast<float>(b),
                           pbr.BaseColor.Alpha()};
    for (int k = 0; k < 4; ++k) material.baseColor[k] = base[k];
    material.metallic = pbr.Metallic;
    material.roughness = pbr.Roughness;
    for (int k = 0; k < 3; ++k) material.emissive[k] = pbr.EmissiveFactor[k];
    const Graphic3d_AlphaMode alpha = vis->AlphaMode();
    material.alphaMode = alpha == Graphic3d_AlphaMode_Mask    ? 1
                         : alpha == Graphic3d_AlphaMode_Blend ? 2
                         : alpha == Graphic3d_AlphaMode_BlendAuto && (translucent || base[3] < 1)
                             ? 2
                             : 0;
    material.alphaCutoff = vis->AlphaCutOff();
    // OCCT's Auto culls the back faces of closed solids only.
    material.doubleSided = vis->FaceCulling() == Graphic3d_TypeOfBackfacingModel_DoubleSided ||
                           (vis->FaceCulling() == Graphic3d_TypeOfBackfacingModel_Auto && open);
  } else if (translucent) {
    material.name = "translucent";
    material.alphaMode = 2;
    material.doubleSided = true;
    material.roughness = 0.1f;
  } else if (open) {
    material.name = "double-sided";
    material.doubleSided = true;
  } else {
    return ~0u;
  }
  const auto index = static_cast<std::uint32_t>(
      std::find(out.materials.begin(), out.materials.end(), material) - out.materials.begin());
  if (index == out.materials.size()) out.materials.push_back(material);
  return index;
}

// One placed instance's faces appended: positions in metres, normals and colours per vertex.
void appendInstance(const Placed& placed, bool open, double metresPerUnit, Result& out) {
  Instance instance{
      placed.name, placed.path, placed.layer, out.positions.size() / 3, 0, out.indices.size() / 3,
      0,           placed.shape};
  const Quantity_ColorRGBA grey(Quantity_Color(0.78, 0.78, 0.78, Quantity_TOC_sRGB));
  bool translucent = false;
  for (RWMesh_FaceIterator face(placed.label, placed.location, true, placed.style); face.More();
       face.Next()) {
    if (face.IsEmptyMesh()) continue;
    const std::uint64_t first = out.positions.size() / 3 - instance.firstVertex;
    out.coloured |= face.HasFaceColor();
    const Quantity_ColorRGBA& color = face.HasFaceColor() ? face.FaceColor() : grey;
    translucent |= color.Alpha() < 1.0f;
    for (Standard_Integer n = face.NodeLower(); n <= face.NodeUpper(); ++n) {
      const gp_Pnt p = face.NodeTransformed(n);
      out.positions.insert(out.positions.end(),
                           {p.X() * metresPerUnit, p.Y() * metresPerUnit, p.Z() * metresPerUnit});
      const gp_Dir d = face.NormalTransformed(n);
      out.normals.insert(out.normals.end(), {static_cast<float>(d.X()), static_cast<float>(d.Y()),
                                             static_cast<float>(d.Z())});
      pushColor(color, out.colors);
    }
    const auto local = [&](Standard_Integer node) {
      return static_cast<std::uint32_t>(first +
                                        static_cast<std::uint64_t>(node - face.NodeLower()));
    };
    for (Standard_Integer t = face.ElemLower(); t <= face.ElemUpper(); ++t) {
      Standard_Integer a = 0, b = 0, c = 0;
      face.TriangleOriented(t).Get(a, b, c);
      out.indices.insert(out.indices.end(), {local(a), local(b), local(c)});
    }
  }
  instance.vertexCount = out.positions.size() / 3 - instance.firstVertex;
  instance.triangleCount = out.indices.size() / 3 - instance.firstTriangle;
  instance.material = materialOf(placed.style, translucent, open, out);
  out.instances.push_back(std::move(instance));
}

// A warning for each shape OCCT could not mesh, wholly or in some faces, named by its part.
void warnUnmeshed(const Tree& tree, const std::vector<std::string>& failures, Result& out) {
  std::vector<bool> warned(tree.shapes.size());
  for (const Placed& placed : tree.placed) {
    if (warned[placed.shape]) continue;
    warned[placed.shape] = true;
    const std::string name = placed.name.empty() ? "(unnamed)" : placed.name;
    if (!failures[placed.shape].empty()) {
      out.warnings.push_back(
          fmt::format("part \"{}\": {}; left out", name, failures[placed.shape]));
      continue;
    }
    const std::uint32_t missing =
        facesWithoutTriangles(XCAFDoc_ShapeTool::GetShape(tree.shapes[placed.shape]));
    if (missing > 0)
      out.warnings.push_back(
          fmt::format("part \"{}\": {} face(s) did not mesh; left out", name, missing));
  }
}

// What a failure of the whole read tells the user. A crash inside OCCT (a signal OcctSignals
// turned into a failure) says so; the address in OCCT's own message is of no use to them.
std::string describe(const Standard_Failure& failure) {
  if (failure.IsKind(STANDARD_TYPE(OSD_Signal)))
    return fmt::format(
        "OCCT crashed reading it ({}): the file is damaged, or beyond what OCCT can read",
        failure.DynamicType()->Name());
  return fmt::format("OCCT failed: {} {}", failure.DynamicType()->Name(),
                     failure.GetMessageString());
}

// One read at a time (OCCT's reader statics and the signal handlers are process-wide).
void read(const Request& request, Result& out) {
  Handle(TDocStd_Document) doc;
  if (std::optional<Failure> failed = readDocument(request, doc, out.lost)) {
    out.status = failed->status;
    out.error = failed->message;
    if (!doc.IsNull()) XCAFApp_Application::GetApplication()->Close(doc);
    return;
  }
  Standard_Real metresPerUnit = 1;
  if (cadFormat(request.path) == CadFormat::kBrep ||
      !XCAFDoc_DocumentTool::GetLengthUnit(doc, metresPerUnit) || !(metresPerUnit > 0))
    metresPerUnit = 1;
  const Tree tree = walkTree(doc, request.hidden);
  const std::vector<std::string> failures = tessellate(tree, request, metresPerUnit);
  if (isCancelled(request)) {
    XCAFApp_Application::GetApplication()->Close(doc);
    out = {};
    out.status = 3;
    out.error = "cancelled";
    return;
  }
  const std::vector<char> open = openShapes(tree);
  for (const Placed& placed : tree.placed)
    appendInstance(placed, open[placed.shape] != 0, metresPerUnit, out);
  if (!out.coloured) out.colors.clear();
  warnUnmeshed(tree, failures, out);
  out.shapes = tree.shapes.size();
  out.depth = tree.depth;
  out.hidden = tree.hidden;
  XCAFApp_Application::GetApplication()->Close(doc);
  if (out.indices.empty()) {
    out.status = 1;
    out.error = !tree.placed.empty() ? "no part could be meshed (see the warnings)"
                : tree.hidden > 0    ? "the file hides every part in it (--hidden keeps them)"
                                     : "no shape in the file";
  }
}

}  // namespace
}  // namespace lodforge::cad

// No OCCT exception leaves the module: a failure outside a part's meshing fails the read.
extern "C" __attribute__((visibility("default"))) void lodforge_cad_read(
    int version, const lodforge::cad::Request& request, lodforge::cad::Result& result) {
  result = {};
  if (version != lodforge::cad::kModuleVersion) {
    result.status = 1;
    result.error = fmt::format("the CAD module is version {}, lodforge wants {}",
                               lodforge::cad::kModuleVersion, version);
    return;
  }
  try {
    const std::lock_guard lock(lodforge::cad::occt().reading);
    const lodforge::cad::OcctSignals signals;
    lodforge::cad::guarded([&] { lodforge::cad::read(request, result); });
  } catch (const Standard_Failure& failure) {
    result = {};
    result.status = 1;
    result.error = lodforge::cad::describe(failure);
  } catch (const std::exception& failure) {
    result = {};
    result.status = 1;
    result.error = fmt::format("reading failed: {}", failure.what());
  }
}
