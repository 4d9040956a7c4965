#include "lodforge/tiling/vertex_cache.h"

#include <unistd.h>

#include <algorithm>
#include <cassert>
#include <cstring>

namespace lodforge {
namespace {

constexpr std::uint64_t kBlockVertices = 1 << 14;

}  // namespace

void writeVertexRecord(std::byte* record, const VertexLayout& layout, Vec3d position, Rgba8 color,
                       Vec3f normal, Vec2f uv) {
  if (layout.floatPositions) {
    const float xyz[3] = {static_cast<float>(position.x), static_cast<float>(position.y),
                          static_cast<float>(position.z)};
    std::memcpy(record, xyz, sizeof xyz);
  } else {
    const double xyz[3] = {position.x, position.y, position.z};
    std::memcpy(record, xyz, sizeof xyz);
  }
  const float n[3] = {normal.x, normal.y, normal.z};
  std::memcpy(record + layout.positionBytes(), &color, sizeof color);
  std::memcpy(record + layout.normalOffset(), n, sizeof n);
  if (layout.uvs) std::memcpy(record + layout.uvOffset(), &uv, sizeof uv);
}

VertexCache::VertexCache(int fd, std::uint64_t vertices, std::uint64_t bytes, VertexLayout layout)
    : VertexCache(fd, vertices, bytes, layout.bytes()) {
  layout_ = layout;
}

VertexCache::VertexCache(int fd, std::uint64_t vertices, std::uint64_t bytes,
                         std::size_t recordBytes)
    : fd_(fd), vertices_(vertices), recordBytes_(recordBytes) {
  const std::uint64_t blockBytes = kBlockVertices * recordBytes_;
  slots_ = std::max<std::uint64_t>(4, bytes / blockBytes);
  data_.resize(slots_ * blockBytes);
  tags_.assign(slots_, ~std::uint64_t{0});
  dirty_.assign(slots_, 0);
}

bool VertexCache::fetch(std::uint64_t vertex, CutCorner& out) {
  assert(layout_);
  const std::byte* at = record(vertex);
  if (at == nullptr) return false;
  if (layout_->floatPositions) {
    float xyz[3];
    std::memcpy(xyz, at, sizeof xyz);
    out.position = {xyz[0], xyz[1], xyz[2]};
  } else {
    double xyz[3];
    std::memcpy(xyz, at, sizeof xyz);
    out.position = {xyz[0], xyz[1], xyz[2]};
  }
  float normal[3];
  std::memcpy(&out.color, at + layout_->positionBytes(), sizeof(Rgba8));
  std::memcpy(normal, at + layout_->normalOffset(), sizeof normal);
  out.normal = normalizeOr(Vec3f{normal[0], normal[1], normal[2]}, Vec3f{0, 0, 1});
  if (layout_->uvs) std::memcpy(&out.uv, at + layout_->uvOffset(), sizeof(Vec2f));
  out.source = vertex;
  return true;
}

bool VertexCache::addNormal(std::uint64_t vertex, Vec3f add) {
  assert(layout_);
  std::byte* at = record(vertex);
  if (at == nullptr) return false;
  float normal[3];
  std::memcpy(normal, at + layout_->normalOffset(), sizeof normal);
  normal[0] += add.x, normal[1] += add.y, normal[2] += add.z;
  std::memcpy(at + layout_->normalOffset(), normal, sizeof normal);
  dirty_[vertex / kBlockVertices % slots_] = 1;
  return true;
}

bool VertexCache::flush() {
  for (std::uint64_t slot = 0; slot < slots_; ++slot)
    if (dirty_[slot] != 0 && !writeBack(slot)) return false;
  return true;
}

std::byte* VertexCache::record(std::uint64_t vertex) {
  if (vertex >= vertices_) return nullptr;
  const std::uint64_t block = vertex / kBlockVertices;
  const std::uint64_t slot = block % slots_;
  std::byte* base = data_.data() + slot * kBlockVertices * recordBytes_;
  if (tags_[slot] != block) {
    if (dirty_[slot] != 0 && !writeBack(slot)) return nullptr;
    const std::uint64_t first = block * kBlockVertices;
    const auto wanted = static_cast<std::size_t>(blockVertices(block) * recordBytes_);
    if (::pread(fd_, base, wanted, static_cast<off_t>(first * recordBytes_)) !=
        static_cast<ssize_t>(wanted))
      return nullptr;
    tags_[slot] = block;
  }
  return base + (vertex % kBlockVertices) * recordBytes_;
}

std::uint64_t VertexCache::blockVertices(std::uint64_t block) const {
  return std::min(kBlockVertices, vertices_ - block * kBlockVertices);
}

bool VertexCache::writeBack(std::uint64_t slot) {
  const std::uint64_t block = tags_[slot];
  const auto bytes = static_cast<std::size_t>(blockVertices(block) * recordBytes_);
  const std::byte* base = data_.data() + slot * kBlockVertices * recordBytes_;
  if (::pwrite(fd_, base, bytes, static_cast<off_t>(block * kBlockVertices * recordBytes_)) !=
      static_cast<ssize_t>(bytes))
    return false;
  dirty_[slot] = 0;
  return true;
}

}  // namespace lodforge
