#include "lodforge/io/mesh/assimp_reader.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <assimp/Importer.hpp>
#include <assimp/ProgressHandler.hpp>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/mesh/assimp_textures.h"

namespace lodforge {

namespace {

// What we hand to assimp: scenes of meshes. Formats we read ourselves (PLY, OBJ, STL, glTF,
// STEP) and animation-only ones (BVH, MD5 animations) are not in the list.
constexpr std::array<std::string_view, 20> kExtensions = {
    "off", "fbx", "dae",  "zae", "3ds", "3mf",  "ifc", "ifczip", "x3d",  "x3db",
    "x",   "ac",  "ac3d", "ase", "lwo", "ms3d", "b3d", "dxf",    "ogex", "xgl"};

// Ctrl-C between assimp's steps: returning false makes ReadFile give up.
class CancelOnInterrupt final : public Assimp::ProgressHandler {
 public:
  bool Update(float) override { return !cancelRequested(); }
};

float unit(float x) {
  return std::isfinite(x) ? std::clamp(x, 0.0f, 1.0f) : 0.0f;
}

// assimp's material keys as glTF's metallic-roughness model. Opacity below 1 (IFC's and
// Collada's transparency, FBX's TransparencyFactor) is BLEND and double-sided, as glass is.
Material convertMaterial(const aiMaterial& m) {
  Material out;
  if (aiString name; m.Get(AI_MATKEY_NAME, name) == AI_SUCCESS) out.name = name.C_Str();
  aiColor4D color;
  if (m.Get(AI_MATKEY_BASE_COLOR, color) == AI_SUCCESS ||
      m.Get(AI_MATKEY_COLOR_DIFFUSE, color) == AI_SUCCESS)
    out.baseColor = {unit(color.r), unit(color.g), unit(color.b), unit(color.a)};
  // An opacity of exactly 0 is what several exporters write for "not set"; an invisible part
  // is never what a user means.
  if (float opacity = 1; m.Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS && opacity > 0)
    out.baseColor[3] *= unit(opacity);
  if (float metallic = 0; m.Get(AI_MATKEY_METALLIC_FACTOR, metallic) == AI_SUCCESS)
    out.metallic = unit(metallic);
  if (float roughness = 0; m.Get(AI_MATKEY_ROUGHNESS_FACTOR, roughness) == AI_SUCCESS)
    out.roughness = unit(roughness);
  if (aiColor3D emissive; m.Get(AI_MATKEY_COLOR_EMISSIVE, emissive) == AI_SUCCESS)
    out.emissive = {unit(emissive.r), unit(emissive.g), unit(emissive.b)};
  // Most interchange formats do not say whether a surface is closed: both sides unless the file
  // says one (assimp's DefaultMaterial, given to meshes without one, says nothing).
  out.doubleSided = true;
  if (int twoSided = 1; m.Get(AI_MATKEY_TWOSIDED, twoSided) == AI_SUCCESS)
    out.doubleSided = twoSided != 0;
  if (out.baseColor[3] < 1) {
    out.alphaMode = AlphaMode::kBlend;
    out.doubleSided = true;
  }
  return out;
}

Mat4d toMat4d(const aiMatrix4x4& a) {
  // aiMatrix4x4 is row-major (a1..a4 the first row); Mat4d is column-major.
  const float rows[4][4] = {{a.a1, a.a2, a.a3, a.a4},
                            {a.b1, a.b2, a.b3, a.b4},
                            {a.c1, a.c2, a.c3, a.c4},
                            {a.d1, a.d2, a.d3, a.d4}};
  Mat4d m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m.at(r, c) = rows[r][c];
  return m;
}

std::uint8_t channel(double x) {
  return static_cast<std::uint8_t>(
      std::lround(std::clamp(std::isfinite(x) ? x : 0.0, 0.0, 1.0) * 255));
}

// assimp's grey stand-in for a mesh the file gives no material: unnamed or "DefaultMaterial",
// diffuse 0.6 grey (or none), no texture.
bool isStandIn(const aiMaterial& m) {
  aiString name;
  const bool named = m.Get(AI_MATKEY_NAME, name) == AI_SUCCESS && name.length > 0 &&
                     std::string_view(name.C_Str()) != AI_DEFAULT_MATERIAL_NAME;
  aiColor4D diffuse(0.6f, 0.6f, 0.6f, 1.0f);
  m.Get(AI_MATKEY_COLOR_DIFFUSE, diffuse);
  const bool grey = diffuse.r == 0.6f && diffuse.g == 0.6f && diffuse.b == 0.6f && diffuse.a == 1;
  return !named && grey && m.GetTextureCount(aiTextureType_DIFFUSE) == 0 &&
         m.GetTextureCount(aiTextureType_BASE_COLOR) == 0;
}

// The scene's node tree walked from the root, every mesh reference an object.
class SceneConverter {
 public:
  SceneConverter(const aiScene& scene, const std::string& path, std::vector<std::string>* warnings)
      : scene_(scene), path_(path), warnings_(warnings) {}

  Result<Model> convert() {
    convertMaterials();
    // (From memory, for the fuzzer: no texture file beside it to read.)
    if (warnings_ != nullptr || scene_.mNumTextures > 0)
      texturing_ = readAssimpTextures(scene_, materialOf_, path_, model_, warnings_);
    withUvs_ = std::any_of(texturing_.uvChannel.begin(), texturing_.uvChannel.end(),
                           [](int channel) { return channel >= 0; });
    withColors_ =
        !model_.materials.empty() ||
        std::any_of(scene_.mMeshes, scene_.mMeshes + scene_.mNumMeshes, [](const aiMesh* mesh) {
          return hasTriangles(*mesh) && mesh->HasVertexColors(0);
        });
    walk();
    if (!problem_.empty()) return badInput(path_, problem_);
    if (model_.triangleCount() == 0)
      return badInput(path_, "the scene holds no triangles (only points, lines or nothing)");
    placeAtOrigin();
    if (warnings_ != nullptr && skippedFaces_ > 0)
      warnings_->push_back(fmt::format("{}: {} point and line faces not read: only triangles are",
                                       path_, skippedFaces_));
    return std::move(model_);
  }

 private:
  struct Visit {
    const aiNode* node;
    Mat4d parent;
    std::string path;  // of the parent
  };

  // The file's materials. assimp gives a mesh without one a grey stand-in of its own (OFF's
  // loader an unnamed one, the others "DefaultMaterial"): no colour of the file's, so it is left
  // out (an OFF file has no colours, and says none).
  void convertMaterials() {
    materialOf_.assign(scene_.mNumMaterials, kNoMaterial);
    for (unsigned m = 0; m < scene_.mNumMaterials; ++m) {
      if (isStandIn(*scene_.mMaterials[m])) continue;
      materialOf_[m] = static_cast<std::uint32_t>(model_.materials.size());
      model_.materials.push_back(convertMaterial(*scene_.mMaterials[m]));
    }
  }

  // Depth first, children in file order. assimp's root is its own container: its name starts
  // no path unless it draws meshes itself.
  void walk() {
    std::vector<Visit> stack = {{scene_.mRootNode, Mat4d{}, {}}};
    std::size_t visited = 0;
    while (!stack.empty()) {
      const Visit visit = std::move(stack.back());
      stack.pop_back();
      const aiNode& node = *visit.node;
      const Mat4d world = visit.parent * toMat4d(node.mTransformation);
      const std::string name =
          node.mName.length > 0 ? node.mName.C_Str() : fmt::format("node {}", visited);
      ++visited;
      const std::vector<unsigned> surfaces = surfaceMeshes(node);
      const bool container = &node == scene_.mRootNode && surfaces.empty();
      const std::string path = container            ? std::string{}
                               : visit.path.empty() ? name
                                                    : visit.path + "/" + name;
      for (std::size_t k = 0; k < surfaces.size(); ++k) {
        const std::string suffix = surfaces.size() > 1 ? fmt::format("#{}", k) : std::string{};
        addObject(name + suffix, path + suffix, surfaces[k], world);
      }
      for (unsigned c = node.mNumChildren; c-- > 0;)
        stack.push_back({node.mChildren[c], world, path});
    }
  }

  // The node's meshes with triangles, in order. SortByPType gave points and lines meshes of
  // their own: they are not surfaces, and are counted (numbering skips them, as when assimp
  // removed them).
  std::vector<unsigned> surfaceMeshes(const aiNode& node) {
    std::vector<unsigned> surfaces;
    for (unsigned k = 0; k < node.mNumMeshes; ++k) {
      const unsigned m = node.mMeshes[k];
      if (m >= scene_.mNumMeshes) continue;
      if (hasTriangles(*scene_.mMeshes[m]))
        surfaces.push_back(m);
      else
        skippedFaces_ += scene_.mMeshes[m]->mNumFaces;
    }
    return surfaces;
  }
  static bool hasTriangles(const aiMesh& mesh) {
    return (mesh.mPrimitiveTypes & aiPrimitiveType_TRIANGLE) != 0;
  }

  void addObject(const std::string& name, const std::string& path, unsigned meshIndex,
                 const Mat4d& world) {
    if (meshIndex >= scene_.mNumMeshes) return;
    const aiMesh& mesh = *scene_.mMeshes[meshIndex];
    ModelBuilder builder(model_);
    builder.beginObject(name, path);
    const std::uint32_t material =
        mesh.mMaterialIndex < materialOf_.size() ? materialOf_[mesh.mMaterialIndex] : kNoMaterial;
    model_.objects.back().material = material;
    const Mat4d normalMatrix = world.normalMatrix();
    const bool mirrored = world.determinant3() < 0;
    const std::array<float, 4> factor = material != kNoMaterial
                                            ? model_.materials[material].baseColor
                                            : std::array<float, 4>{1, 1, 1, 1};
    for (unsigned v = 0; v < mesh.mNumVertices; ++v) {
      const aiVector3D& p = mesh.mVertices[v];
      world_.push_back(world.transformPoint({p.x, p.y, p.z}));
      if (!isFinite(world_.back()) && problem_.empty())
        problem_ =
            fmt::format("mesh {} ('{}') vertex {} is not finite", meshIndex, mesh.mName.C_Str(), v);
      model_.positions.push_back({});  // filled by placeAtOrigin
      if (mesh.HasNormals()) {
        const aiVector3D& n = mesh.mNormals[v];
        normals_.push_back(
            toFloat(normalizeOr(normalMatrix.transformVector({n.x, n.y, n.z}), Vec3d{})));
      } else {
        normals_.push_back({});
        missingNormals_ = true;
      }
      if (withUvs_) model_.uvs.push_back(uvOf(mesh, material, v));
      if (withColors_) {
        std::array<double, 4> c = {factor[0], factor[1], factor[2], factor[3]};
        if (mesh.HasVertexColors(0)) {
          const aiColor4D& vc = mesh.mColors[0][v];
          c = {c[0] * vc.r, c[1] * vc.g, c[2] * vc.b, c[3] * vc.a};
        }
        model_.colors.push_back({channel(c[0]), channel(c[1]), channel(c[2]), channel(c[3])});
      }
    }
    for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
      const aiFace& face = mesh.mFaces[f];
      if (face.mNumIndices != 3) {  // points and lines (triangulated before): counted
        ++skippedFaces_;
        continue;
      }
      std::uint32_t a = face.mIndices[0], b = face.mIndices[1], c = face.mIndices[2];
      if (std::max({a, b, c}) >= mesh.mNumVertices) continue;  // validated by assimp
      if (mirrored) std::swap(b, c);
      builder.addTriangle(a, b, c);
    }
    builder.endObject();
  }

  // A vertex's coordinate in its material's texture (assimp's origin is bottom left: v turned
  // to glTF's way); a mesh without that channel samples the texture's corner.
  Vec2f uvOf(const aiMesh& mesh, std::uint32_t material, unsigned v) const {
    if (!texturing_.textured(material)) return {};
    const auto channel = static_cast<unsigned>(texturing_.uvChannel[material]);
    if (channel >= AI_MAX_NUMBER_OF_TEXTURECOORDS || mesh.mTextureCoords[channel] == nullptr)
      return {};
    const aiVector3D& uv = mesh.mTextureCoords[channel][v];
    if (!std::isfinite(uv.x) || !std::isfinite(uv.y)) return {};
    return {uv.x, 1.0f - uv.y};
  }

  void placeAtOrigin() {
    lodforge::placeAtOrigin(model_, world_);
    // Normals only when every vertex has one, as the glTF reader keeps them.
    if (!missingNormals_ && !normals_.empty()) model_.normals = std::move(normals_);
  }

  const aiScene& scene_;
  const std::string& path_;
  Model model_;
  std::vector<Vec3d> world_;
  std::vector<Vec3f> normals_;
  std::vector<std::uint32_t> materialOf_;  // a scene material's index in the model's, or none
  std::vector<std::string>* warnings_;
  std::uint64_t skippedFaces_ = 0;  // per placed instance
  AssimpTexturing texturing_;
  bool withColors_ = false;
  bool withUvs_ = false;
  bool missingNormals_ = false;
  std::string problem_;  // the first thing wrong with the scene
};

}  // namespace

bool isAssimpExtension(std::string_view extension) {
  return std::find(kExtensions.begin(), kExtensions.end(), extension) != kExtensions.end();
}

namespace {

// Reads with `read(importer, flags)` (from a file or from memory) and converts the scene.
template <class Read>
Result<Model> import(const std::string& name, std::vector<std::string>* warnings, Read&& read) {
  try {
    Assimp::Importer importer;
    importer.SetProgressHandler(new CancelOnInterrupt);  // the importer owns and deletes it
    const aiScene* scene =
        read(importer, aiProcess_Triangulate | aiProcess_SortByPType |
                           aiProcess_JoinIdenticalVertices | aiProcess_ValidateDataStructure);
    LODFORGE_TRY(checkCancelled());
    if (!scene) return badInput(name, fmt::format("assimp: {}", importer.GetErrorString()));
    if ((scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 || !scene->mRootNode)
      return badInput(name, "assimp read an incomplete scene (no node tree)");
    return SceneConverter(*scene, name, warnings).convert();
  } catch (const std::exception& e) {
    return badInput(name, fmt::format("assimp: {}", e.what()));
  }
}

}  // namespace

Result<Model> readAssimp(const std::string& path, std::vector<std::string>* warnings) {
  Result<std::uint64_t> size = fileSize(path);  // a missing file says so, not assimp's words
  if (!size) return size.status();
  std::vector<std::string> ignored;
  return import(
      path, warnings ? warnings : &ignored,
      [&](Assimp::Importer& importer, unsigned flags) { return importer.ReadFile(path, flags); });
}

Result<Model> readAssimpFromMemory(std::span<const std::byte> bytes, const std::string& name) {
  const std::string hint = fileExtension(name);
  return import(name, nullptr, [&](Assimp::Importer& importer, unsigned flags) {
    return importer.ReadFileFromMemory(bytes.data(), bytes.size(), flags, hint.c_str());
  });
}

}  // namespace lodforge
