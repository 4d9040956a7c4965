// glTF 2.0 reader (.gltf and .glb, through tinygltf). Each node's mesh instance becomes one
// object — a CAD part — with its world transform applied and its primitives merged; instanced
// meshes (several nodes, or EXT_mesh_gpu_instancing) are expanded. Each primitive's base colour
// (times COLOR_0) becomes vertex colour; a base-colour texture becomes the material's image, with
// the texture's TEXCOORD set (through KHR_texture_transform) as the model's UVs
// (gltf_textures.h). KHR_draco_mesh_compression is decoded with libdraco.
#pragma once

#include <span>
#include <string>
#include <vector>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

struct GltfReadOptions {
  // Load buffers named by relative URIs beside the file. Off for untrusted in-memory input.
  bool allowExternalFiles = true;
  // What was read with a loss: a texture image missing or unreadable (its material then draws
  // without it), a textured primitive without texture coordinates, point and line primitives
  // (not read: counted, with the corners they draw).
  std::vector<std::string>* warnings = nullptr;
};

Result<Model> readGltf(const std::string& path, const GltfReadOptions& options = {});
// Detects GLB by its magic, otherwise parses glTF JSON.
Result<Model> readGltfFromMemory(std::span<const std::byte> bytes, const std::string& name,
                                 const GltfReadOptions& options = {});

}  // namespace lodforge
