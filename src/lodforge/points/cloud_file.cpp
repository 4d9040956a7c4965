#include "lodforge/points/cloud_file.h"

#include <algorithm>
#include <cstring>
#include <filesystem>

#include "lodforge/core/checksum.h"
#include "lodforge/core/output_claim.h"

namespace lodforge {

namespace {

struct SegmentHeader {
  char magic[8];
  std::uint32_t version = kCloudVersion;
  std::uint32_t reserved = 0;
  std::uint64_t buildId = 0;
  std::uint64_t block = 0;
  std::uint64_t count = 0;  // records
};
static_assert(sizeof(SegmentHeader) == 40);

std::size_t padded(std::size_t bytes) {
  return (bytes + 7) / 8 * 8;
}

}  // namespace

std::string segmentDirectoryFor(const std::string& cloudPath) {
  std::filesystem::path p(cloudPath);
  p.replace_extension(".lfs");
  return p.string();
}

Status claimPointPackageOutput(const std::string& input, const std::string& output) {
  const std::string inputs[] = {input};
  const OutputKind package{.name = "a point package (.lfc)", .isOwn = [](const std::string& p) {
                             return fileStartsWith(p, std::string_view(kCloudMagic, 8));
                           }};
  LODFORGE_TRY(claimOutput(output, package, inputs));
  const OutputKind segments{.name = "the segment directory of a point package",
                            .directory = true,
                            .isOwn = [](const std::string& directory) {
                              return directoryHoldsOnly(
                                  directory, [](const std::string& name, bool isDirectory) {
                                    return !isDirectory && name.size() == 16 &&
                                           name.starts_with("block-") && name.ends_with(".seg") &&
                                           std::all_of(name.begin() + 6, name.begin() + 12,
                                                       [](char c) { return c >= '0' && c <= '9'; });
                                  });
                            }};
  return claimOutput(segmentDirectoryFor(output), segments, inputs);
}

std::string segmentFileName(std::uint64_t block) {
  return fmt::format("block-{:06}.seg", block);
}

bool childLinksValid(std::span<const ClusterNode> nodes, std::size_t segmentCount) {
  for (const ClusterNode& n : nodes) {
    if (!n.leaf() && (std::size_t{n.firstChild} + 1 >= segmentCount)) return false;
  }
  return true;
}

Status writeSegmentFile(const std::string& path, std::uint64_t buildId, std::uint64_t block,
                        std::span<const ClusterNode> segment) {
  Result<OutputFile> out = OutputFile::create(path, std::size_t{1} << 20);
  if (!out) return out.status();
  SegmentHeader header;
  std::memcpy(header.magic, kSegmentMagic, 8);
  header.buildId = buildId;
  header.block = block;
  header.count = segment.size();
  Checksum64 sum;
  sum.update(&header, sizeof header);
  sum.update(segment.data(), segment.size_bytes());
  const std::uint64_t digest = sum.digest();
  LODFORGE_TRY(out->write(&header, sizeof header));
  LODFORGE_TRY(out->writeSpan(segment));
  LODFORGE_TRY(out->write(&digest, sizeof digest));
  return out->commit();
}

Status writeCloudFile(const std::string& path, CloudHeader header, const std::string& crs,
                      std::span<const CloudBlock> blocks, std::span<const ClusterNode> resident) {
  return writeCloudFile(
      path, header, crs, blocks, [&](std::size_t b) -> Result<std::vector<ClusterNode>> {
        const auto first = resident.begin() + static_cast<std::ptrdiff_t>(blocks[b].residentFirst);
        return std::vector<ClusterNode>(first, first + blocks[b].residentCount);
      });
}

Status writeCloudFile(const std::string& path, CloudHeader header, const std::string& crs,
                      std::span<const CloudBlock> blocks, const ResidentSource& residentOf) {
  std::memcpy(header.magic, kCloudMagic, 8);
  header.version = kCloudVersion;
  header.blockCount = blocks.size();
  header.residentCount = 0;
  for (const CloudBlock& b : blocks) header.residentCount += b.residentCount;
  header.crsBytes = static_cast<std::uint32_t>(crs.size());
  Result<OutputFile> out = OutputFile::create(path);
  if (!out) return out.status();
  std::string crsPadded = crs;
  crsPadded.resize(padded(crs.size()), '\0');
  Checksum64 sum;
  const auto put = [&](const void* data, std::size_t size) {
    sum.update(data, size);
    return out->write(data, size);
  };
  LODFORGE_TRY(put(&header, sizeof header));
  LODFORGE_TRY(put(crsPadded.data(), crsPadded.size()));
  LODFORGE_TRY(put(blocks.data(), blocks.size_bytes()));
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    Result<std::vector<ClusterNode>> part = residentOf(b);
    if (!part) return part.status();
    assert(part->size() == blocks[b].residentCount);
    LODFORGE_TRY(put(part->data(), part->size() * sizeof(ClusterNode)));
  }
  const std::uint64_t digest = sum.digest();
  LODFORGE_TRY(out->write(&digest, sizeof digest));
  return out->commit();
}

Result<CloudFile> CloudFile::open(const std::string& path) {
  Result<MappedFile> mapped = MappedFile::open(path);
  if (!mapped) return mapped.status();
  CloudFile cloud;
  cloud.file_.emplace(std::move(*mapped));
  cloud.bytes_ = cloud.file_->bytes();
  cloud.path_ = path;
  return parse(std::move(cloud));
}

Result<CloudFile> CloudFile::fromBytes(std::span<const std::byte> bytes, const std::string& name) {
  CloudFile cloud;
  cloud.bytes_ = bytes;
  cloud.path_ = name;
  return parse(std::move(cloud));
}

Result<CloudFile> CloudFile::parse(CloudFile cloud) {
  const std::span<const std::byte> bytes = cloud.bytes_;
  const std::string& path = cloud.path_;
  if (bytes.size() < sizeof(CloudHeader) + 8)
    return badInputAtByte(path, 0, "too short for a point package");
  std::memcpy(&cloud.header_, bytes.data(), sizeof(CloudHeader));
  const CloudHeader& h = cloud.header_;
  if (std::memcmp(h.magic, kCloudMagic, 8) != 0)
    return badInputAtByte(path, 0, "not a point package (.lfc): wrong magic");
  if (h.version != kCloudVersion)
    return badInputAtByte(
        path, 8,
        fmt::format("version {} is not supported (this build reads {})", h.version, kCloudVersion));
  std::uint64_t digest = 0;
  std::memcpy(&digest, bytes.data() + bytes.size() - 8, 8);
  if (checksum64(bytes.first(bytes.size() - 8)) != digest)
    return badInputAtByte(path, bytes.size() - 8, "checksum mismatch: the package is corrupted");
  // With the checksum right, the sizes are what the writer wrote; still check them against the
  // file so a hand-made header cannot send us out of bounds.
  const std::uint64_t crsAt = sizeof(CloudHeader);
  const std::uint64_t tableAt = crsAt + padded(h.crsBytes);
  const std::uint64_t residentAt = tableAt + h.blockCount * sizeof(CloudBlock);
  if (h.blockCount > bytes.size() / sizeof(CloudBlock) ||
      h.residentCount > bytes.size() / sizeof(ClusterNode) ||
      residentAt + h.residentCount * sizeof(ClusterNode) + 8 != bytes.size())
    return badInputAtByte(path, 24, "the counts in the header do not match the file's size");
  cloud.crs_.assign(reinterpret_cast<const char*>(bytes.data() + crsAt), h.crsBytes);
  cloud.blocks_ = {reinterpret_cast<const CloudBlock*>(bytes.data() + tableAt),
                   static_cast<std::size_t>(h.blockCount)};
  cloud.resident_ = {reinterpret_cast<const ClusterNode*>(bytes.data() + residentAt),
                     static_cast<std::size_t>(h.residentCount)};
  for (std::size_t b = 0; b < cloud.blocks_.size(); ++b) {
    const CloudBlock& block = cloud.blocks_[b];
    if (block.residentFirst + block.residentCount > h.residentCount ||
        !childLinksValid(cloud.residentOf(b), block.segmentCount))
      return badInputAtByte(path, tableAt + b * sizeof(CloudBlock),
                            fmt::format("block {}: its records point outside the package", b));
  }
  return cloud;
}

Result<std::vector<ClusterNode>> CloudFile::loadSegment(std::size_t block) const {
  const std::string path = segmentDirectoryFor(path_) + "/" + segmentFileName(block);
  Result<std::string> text = readFileToString(path, std::uint64_t{1} << 34);
  if (!text) return text.status();
  const std::string& bytes = *text;
  SegmentHeader header;
  if (bytes.size() < sizeof header + 8)
    return badInputAtByte(path, 0, "too short for a segment file");
  std::memcpy(&header, bytes.data(), sizeof header);
  if (std::memcmp(header.magic, kSegmentMagic, 8) != 0)
    return badInputAtByte(path, 0, "not a segment file: wrong magic");
  if (header.version != kCloudVersion) return badInputAtByte(path, 8, "unsupported version");
  if (header.buildId != header_.buildId || header.block != block)
    return badInputAtByte(path, 16,
                          fmt::format("belongs to another build or block than {}", path_));
  const CloudBlock& entry = blocks_[block];
  if (header.count != entry.segmentCount ||
      bytes.size() != sizeof header + header.count * sizeof(ClusterNode) + 8)
    return badInputAtByte(path, 32, "record count does not match the package or the file size");
  std::uint64_t digest = 0;
  std::memcpy(&digest, bytes.data() + bytes.size() - 8, 8);
  if (checksum64({reinterpret_cast<const std::byte*>(bytes.data()), bytes.size() - 8}) != digest)
    return badInputAtByte(path, bytes.size() - 8, "checksum mismatch: the segment is corrupted");
  std::vector<ClusterNode> nodes(header.count);
  if (!nodes.empty())
    std::memcpy(nodes.data(), bytes.data() + sizeof header, nodes.size() * sizeof(ClusterNode));
  bool forward = true;  // children after their parent: a walk down always ends
  for (std::size_t i = 0; i < nodes.size(); ++i)
    forward = forward && (nodes[i].leaf() || nodes[i].firstChild > i);
  if (!forward || !childLinksValid(nodes, nodes.size()))
    return badInputAtByte(path, sizeof header, "a record's children lie outside the segment");
  return nodes;
}

}  // namespace lodforge
