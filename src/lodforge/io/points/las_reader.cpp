#include "lodforge/io/points/las_reader.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <optional>

#include "lodforge/io/points/las_format.h"
#include "lodforge/io/points/laz/laz_reader.h"
#include "lodforge/io/points/record_field.h"

namespace lodforge {

namespace {

// Public header block: where each field sits (LAS 1.4 R15, Table 3; earlier versions are
// prefixes of it).
constexpr std::size_t kHeader12 = 227, kHeader13 = 235, kHeader14 = 375;
using las::kEvlrHeader, las::kVlrHeader;
constexpr std::uint16_t kWktRecord = 2112, kGeoKeyRecord = 34735, kExtraBytesRecord = 4;
constexpr std::uint16_t kProjectedCsKey = 3072, kGeographicKey = 2048, kUserDefined = 32767;
constexpr std::size_t kColorProbe = 1 << 16;  // points looked at to tell 8- from 16-bit colours

// Where a format keeps red, green, blue (three uint16), 0 when it has no colour.
std::size_t colorOffset(int format) {
  switch (format) {
    case 2:
      return 20;
    case 3:
    case 5:
      return 28;
    case 7:
    case 8:
    case 10:
      return 30;
    default:
      return 0;
  }
}

// "EPSG:N" from a GeoKeyDirectoryTag: the projected system, else the geographic one.
std::string epsgFromGeoKeys(std::span<const std::uint16_t> keys) {
  if (keys.size() < 4) return {};
  const std::size_t count = std::min<std::size_t>(keys[3], (keys.size() - 4) / 4);
  std::uint16_t projected = 0, geographic = 0;
  for (std::size_t k = 0; k < count; ++k) {
    const std::uint16_t id = keys[4 + 4 * k], location = keys[5 + 4 * k], value = keys[7 + 4 * k];
    if (location != 0 || value == 0 || value == kUserDefined) continue;  // not a plain code
    if (id == kProjectedCsKey) projected = value;
    if (id == kGeographicKey) geographic = value;
  }
  const std::uint16_t code = projected != 0 ? projected : geographic;
  return code != 0 ? fmt::format("EPSG:{}", code) : std::string{};
}

// The lidar fields every format has, GPS time where it has one, NIR in formats 8 and 10.
std::uint32_t formatAttributes(int format) {
  std::uint32_t bits = kAttrIntensity | kAttrClassification | kAttrReturns | kAttrFlags |
                       kAttrScanAngle | kAttrUserData | kAttrPointSource;
  if (format != 0 && format != 2) bits |= kAttrGpsTime;
  if (format == 8 || format == 10) bits |= kAttrNir;
  return bits;
}

// A record's lidar fields: formats 0–5 (LAS 1.0–1.3 layout) and 6–10 (LAS 1.4 R15, Table 17).
PointAttributes recordAttributes(const std::byte* r, int format) {
  PointAttributes a;
  a.intensity = loadField<std::uint16_t>(r + 12);
  const auto b14 = static_cast<std::uint8_t>(r[14]), b15 = static_cast<std::uint8_t>(r[15]);
  if (format < 6) {
    a.returnNumber = b14 & 7;
    a.numberOfReturns = (b14 >> 3) & 7;
    a.flags = static_cast<std::uint8_t>((b14 & 0xC0) | (b15 >> 5));  // direction, edge; 3 flags
    a.classification = b15 & 31;
    a.scanAngle = loadField<std::int8_t>(r + 16);
    a.userData = static_cast<std::uint8_t>(r[17]);
    a.pointSource = loadField<std::uint16_t>(r + 18);
    if (format == 1 || format >= 3) a.gpsTime = loadField<double>(r + 20);
  } else {
    a.returnNumber = b14 & 15;
    a.numberOfReturns = b14 >> 4;
    a.flags = b15;
    a.classification = static_cast<std::uint8_t>(r[16]);
    a.userData = static_cast<std::uint8_t>(r[17]);
    a.scanAngle = static_cast<float>(loadField<std::int16_t>(r + 18) * 0.006);
    a.pointSource = loadField<std::uint16_t>(r + 20);
    a.gpsTime = loadField<double>(r + 22);
    if (format == 8 || format == 10) a.nir = loadField<std::uint16_t>(r + 36);
  }
  return a;
}

}  // namespace

std::uint16_t lasRecordSize(int pointFormat) {
  static constexpr std::uint16_t kSizes[] = {20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67};
  return pointFormat >= 0 && pointFormat <= 10 ? kSizes[pointFormat] : 0;
}

struct CrsRecords;

struct LasReader::State {
  std::string path;                   // to open a second reader for the EVLRs and the probe
  std::span<const std::byte> memory;  // or the bytes of an in-memory file
  std::optional<ByteSource> source;
  LasHeader header;
  std::size_t batchSize = 1 << 16;
  std::uint64_t nextPoint = 0;
  std::uint64_t endPoint = ~std::uint64_t{0};  // restrictTo's end (clipped to pointCount)
  std::size_t rgb = 0;
  std::vector<std::byte> records;
  std::uint8_t formatByte = 0;   // as stored (LASzip sets its top bits)
  std::uint64_t evlrOffset = 0;  // LAS 1.4's extended records
  std::uint32_t evlrCount = 0;
  bool headerOnly = false;           // readHeader: LAZ accepted, no point read
  std::vector<std::byte> lazRecord;  // the LASzip record's data, and where it lies
  std::uint64_t lazAt = 0;
  std::optional<LazPointStream> lazPoints;  // LAZ: the decoded point records
  // The Extra Bytes records (VLRs, then EVLRs), each with the byte its data starts at.
  std::vector<std::pair<std::vector<std::byte>, std::uint64_t>> extraRecords;

  Status readHeader(std::vector<std::byte>& bytes);
  Status readScalesAndBounds(std::span<const std::byte> bytes);
  Status checkPointData() const;
  Status readRecords(CrsRecords& crs);
  Status readExtendedRecords(CrsRecords& crs);
  void readExtraBytes();
  Status probeColorDepth();
  Status readLazRecord();
  Result<LazPointStream> openLazPoints() const;

  Result<ByteSource> reopen() const {
    if (!path.empty()) return ByteSource::openFile(path);
    return ByteSource::fromMemory(memory, source->name());
  }
  Error fail(std::uint64_t at, std::string_view what) const {
    return badInputAtByte(source->name(), at, what);
  }
};

LasReader::LasReader(std::unique_ptr<State> state) : state_(std::move(state)) {}
LasReader::LasReader(LasReader&&) noexcept = default;
LasReader& LasReader::operator=(LasReader&&) noexcept = default;
LasReader::~LasReader() = default;

void LasReader::skipExtraBytes() {
  state_->header.extras = {};
}

const LasHeader& LasReader::header() const {
  return state_->header;
}

Result<LasReader> LasReader::open(const std::string& path, std::size_t batchSize) {
  Result<ByteSource> source = ByteSource::openFile(path);
  if (!source) return source.status();
  auto state = std::make_unique<State>();
  state->path = path;
  state->source.emplace(std::move(*source));
  state->batchSize = std::max<std::size_t>(1, batchSize);
  return start(std::move(state));
}

Result<LasReader> LasReader::fromMemory(std::span<const std::byte> bytes, std::string name,
                                        std::size_t batchSize) {
  auto state = std::make_unique<State>();
  state->memory = bytes;
  state->source.emplace(ByteSource::fromMemory(bytes, std::move(name)));
  state->batchSize = std::max<std::size_t>(1, batchSize);
  return start(std::move(state));
}

// The CRS records (LASF_Projection) met among the VLRs and EVLRs: WKT wins over GeoTIFF keys.
struct CrsRecords {
  std::string wkt, epsg;
  void take(std::uint16_t id, std::string_view user, std::span<const std::byte> data) {
    if (user != "LASF_Projection") return;
    if (id == kWktRecord) {
      wkt = loadText(data.data(), data.size());
    } else if (id == kGeoKeyRecord) {
      std::vector<std::uint16_t> keys(data.size() / 2);
      if (!keys.empty()) std::memcpy(keys.data(), data.data(), 2 * keys.size());
      epsg = epsgFromGeoKeys(keys);
    }
  }
  std::string crs() const { return !wkt.empty() ? wkt : epsg; }
};

// The public header block: version, sizes, counts and the point format (LAZ refused).
Status LasReader::State::readHeader(std::vector<std::byte>& bytes) {
  ByteSource& in = *source;
  LasHeader& h = header;
  const std::uint64_t fileSize = in.size();
  bytes.resize(kHeader12);
  if (!in.read(bytes.data(), kHeader12))
    return fail(
        0, fmt::format("{} bytes are too few for a LAS header ({} bytes)", fileSize, kHeader12));
  if (std::memcmp(bytes.data(), "LASF", 4) != 0)
    return fail(0, "not a LAS file: it does not start with \"LASF\"");
  h.versionMajor = static_cast<int>(bytes[24]);
  h.versionMinor = static_cast<int>(bytes[25]);
  if (h.versionMajor != 1 || h.versionMinor > 4)
    return fail(24, fmt::format("LAS version {}.{} is not supported (1.0 to 1.4 are)",
                                h.versionMajor, h.versionMinor));
  h.systemIdentifier = loadText(bytes.data() + 26, 32);
  h.generatingSoftware = loadText(bytes.data() + 58, 32);
  h.headerSize = loadField<std::uint16_t>(bytes.data() + 94);
  h.pointOffset = loadField<std::uint32_t>(bytes.data() + 96);
  h.vlrCount = loadField<std::uint32_t>(bytes.data() + 100);
  formatByte = static_cast<std::uint8_t>(bytes[104]);
  h.recordLength = loadField<std::uint16_t>(bytes.data() + 105);
  h.pointCount = loadField<std::uint32_t>(bytes.data() + 107);
  const std::size_t wanted = h.versionMinor >= 4   ? kHeader14
                             : h.versionMinor == 3 ? kHeader13
                                                   : kHeader12;
  if (h.headerSize < wanted)
    return fail(94, fmt::format("header size {} is smaller than LAS {}.{}'s {} bytes", h.headerSize,
                                h.versionMajor, h.versionMinor, wanted));
  if (h.headerSize > fileSize)
    return fail(94, fmt::format("header size {} runs past the end of the file ({} bytes)",
                                h.headerSize, fileSize));
  bytes.resize(h.headerSize);
  if (!in.read(bytes.data() + kHeader12, h.headerSize - kHeader12))
    return fail(kHeader12, "the file ends inside the header");
  // LASzip marks compressed files by setting the format's top bits.
  h.compressed = (formatByte & 0xC0) != 0;
  h.pointFormat = formatByte & 0x3F;
  h.attributes = formatAttributes(h.pointFormat);
  if (lasRecordSize(h.pointFormat) == 0)
    return fail(104,
                fmt::format("point format {} is not a LAS format (0 to 10 are)", h.pointFormat));
  if (h.recordLength < lasRecordSize(h.pointFormat))
    return fail(105, fmt::format("point records of {} bytes are shorter than format {}'s {}",
                                 h.recordLength, h.pointFormat, lasRecordSize(h.pointFormat)));
  if (h.versionMinor >= 4) {
    evlrOffset = loadField<std::uint64_t>(bytes.data() + 235);
    evlrCount = loadField<std::uint32_t>(bytes.data() + 243);
    const auto count64 = loadField<std::uint64_t>(bytes.data() + 247);
    if (count64 != 0) h.pointCount = count64;
  }
  return {};
}

// Scale, offset and bounds per axis: finite, and no stored integer overflows a coordinate.
Status LasReader::State::readScalesAndBounds(std::span<const std::byte> bytes) {
  LasHeader& h = header;
  for (int k = 0; k < 3; ++k) {
    h.scale[k] = loadField<double>(bytes.data() + 131 + 8 * static_cast<std::size_t>(k));
    h.offset[k] = loadField<double>(bytes.data() + 155 + 8 * static_cast<std::size_t>(k));
    h.bounds.max[k] = loadField<double>(bytes.data() + 179 + 16 * static_cast<std::size_t>(k));
    h.bounds.min[k] = loadField<double>(bytes.data() + 187 + 16 * static_cast<std::size_t>(k));
    if (!std::isfinite(h.scale[k]) || h.scale[k] == 0)
      return fail(131 + 8 * static_cast<std::uint64_t>(k),
                  fmt::format("scale factor {} is not a finite non-zero number", h.scale[k]));
    if (!std::isfinite(h.offset[k]))
      return fail(155 + 8 * static_cast<std::uint64_t>(k), "offset is not finite");
    // Every stored integer must give a finite coordinate.
    if (!std::isfinite(std::abs(h.scale[k]) * 2147483648.0 + std::abs(h.offset[k])))
      return fail(131 + 8 * static_cast<std::uint64_t>(k),
                  fmt::format("scale factor {} and offset {} overflow a coordinate", h.scale[k],
                              h.offset[k]));
    if (!std::isfinite(h.bounds.min[k]) || !std::isfinite(h.bounds.max[k]))
      return fail(179 + 16 * static_cast<std::uint64_t>(k), "bounds are not finite");
  }
  return {};
}

// The point records lie inside the file, after the header.
Status LasReader::State::checkPointData() const {
  const LasHeader& h = header;
  const std::uint64_t fileSize = source->size();
  // Compressed points take less than their records: only where they start is known here.
  const std::uint64_t pointBytes = h.compressed ? 0 : h.pointCount * h.recordLength;
  if (h.pointOffset < h.headerSize)
    return fail(96, fmt::format("point data offset {} lies inside the {}-byte header",
                                h.pointOffset, h.headerSize));
  if ((!h.compressed && h.pointCount > fileSize / h.recordLength) ||
      h.pointOffset + pointBytes > fileSize)
    return fail(107, fmt::format("{} points of {} bytes from byte {} run past the end of "
                                 "the file ({} bytes)",
                                 h.pointCount, h.recordLength, h.pointOffset, fileSize));

  return {};
}

// Variable length records, between the header and the points.
Status LasReader::State::readRecords(CrsRecords& crs) {
  ByteSource& in = *source;
  const LasHeader& h = header;
  std::vector<std::byte> record;
  for (std::uint32_t v = 0; v < h.vlrCount; ++v) {
    const std::uint64_t at = in.offset();
    std::byte head[kVlrHeader];
    if (at + kVlrHeader > h.pointOffset || !in.read(head, kVlrHeader))
      return fail(at, fmt::format("variable length record {} of {} runs past the point "
                                  "data at byte {}",
                                  v + 1, h.vlrCount, h.pointOffset));
    const auto id = loadField<std::uint16_t>(head + 18);
    const auto length = loadField<std::uint16_t>(head + 20);
    if (at + kVlrHeader + length > h.pointOffset)
      return fail(at + 20, fmt::format("variable length record {} ({} bytes) runs past "
                                       "the point data at byte {}",
                                       v + 1, length, h.pointOffset));
    record.resize(length);
    if (!in.read(record.data(), length)) return fail(at, "the file ends in a record");
    const std::string user = loadText(head + 2, 16);
    crs.take(id, user, record);
    if (user == "laszip encoded" && id == kLazRecordId) {
      lazRecord = record;
      lazAt = at + kVlrHeader;
    }
    if (user == "copc" && id == 1) header.copc = true;
    if (user == "LASF_Spec" && id == kExtraBytesRecord)
      extraRecords.emplace_back(record, at + kVlrHeader);
  }
  return {};
}

// The Extra Bytes records: what the bytes past the point format's hold, every record's
// descriptors in file order. A damaged one never fails the file: the extra bytes are then not
// carried, and extrasIgnored says why.
void LasReader::State::readExtraBytes() {
  LasHeader& h = header;
  if (extraRecords.empty()) return;
  const auto available = static_cast<std::uint32_t>(h.recordLength - lasRecordSize(h.pointFormat));
  std::vector<LasExtraRecord> described;
  for (const auto& [data, at] : extraRecords) described.push_back({data, at});
  Result<PointExtras> extras = parseLasExtraBytes(described, available, source->name());
  if (!extras) {
    // The points themselves are fine: read them without the extra bytes, and say why.
    h.extras = {};
    h.extrasIgnored = extras.error().message + "; the extra bytes are not carried";
    return;
  }
  h.extras = extras->fields.empty() ? PointExtras{} : std::move(*extras);
}

// Extended records (LAS 1.4) follow the points; a second reader fetches them.
Status LasReader::State::readExtendedRecords(CrsRecords& crs) {
  const LasHeader& h = header;
  if (evlrCount == 0) return {};
  const std::uint64_t pointBytes = h.compressed ? 0 : h.pointCount * h.recordLength;
  std::vector<std::byte> record;
  Result<ByteSource> extra = reopen();
  if (!extra) return extra.status();
  if (evlrOffset < h.pointOffset + pointBytes || !extra->skip(evlrOffset))
    return fail(235, fmt::format("extended records at byte {} are not after the points "
                                 "within the file",
                                 evlrOffset));
  for (std::uint32_t v = 0; v < evlrCount; ++v) {
    const std::uint64_t at = extra->offset();
    std::byte head[kEvlrHeader];
    if (!extra->read(head, kEvlrHeader))
      return fail(at, fmt::format("extended record {} of {} runs past the end of the "
                                  "file",
                                  v + 1, evlrCount));
    const auto id = loadField<std::uint16_t>(head + 18);
    const auto length = loadField<std::uint64_t>(head + 20);
    if (length > extra->remaining())
      return fail(at + 20, fmt::format("extended record {} ({} bytes) runs past the "
                                       "end of the file",
                                       v + 1, length));
    const std::string user = loadText(head + 2, 16);
    if (user == "LASF_Projection" && (id == kWktRecord || id == kGeoKeyRecord) &&
        length < (std::uint64_t{1} << 24)) {
      record.resize(length);
      extra->read(record.data(), record.size());
      crs.take(id, user, record);
    } else if (user == "LASF_Spec" && id == kExtraBytesRecord &&
               length < (std::uint64_t{1} << 24)) {
      record.resize(length);
      extra->read(record.data(), record.size());
      extraRecords.emplace_back(record, at + kEvlrHeader);
    } else {
      extra->skip(length);
    }
  }
  return {};
}

// LAZ: the LASzip record must be there and describe the records the header states.
Status LasReader::State::readLazRecord() {
  LasHeader& h = header;
  if (!h.compressed) return {};
  if (lazRecord.empty())
    return fail(104,
                "the point format byte marks LAZ (compressed) points, but the file has no "
                "LASzip record (\"laszip encoded\", 22204)");
  Result<LazInfo> laz = parseLazVlr(lazRecord, source->name(), lazAt);
  if (!laz) return laz.status();
  if (laz->recordBytes() != h.recordLength)
    return fail(lazAt + 32, fmt::format("LASzip items cover {} bytes of a {}-byte point record",
                                        laz->recordBytes(), h.recordLength));
  h.laz = std::move(*laz);
  if (headerOnly) return {};
  Result<LazPointStream> points = openLazPoints();
  if (!points) return points.status();
  lazPoints.emplace(std::move(*points));
  return {};
}

// The compressed points end where LAS 1.4's extended records begin, else at the file's end.
Result<LazPointStream> LasReader::State::openLazPoints() const {
  LazLayout layout;
  layout.file = source->name();
  layout.fileSize = source->size();
  layout.pointOffset = header.pointOffset;
  layout.dataEnd = evlrCount > 0 ? std::min(evlrOffset, layout.fileSize) : layout.fileSize;
  layout.pointCount = header.pointCount;
  layout.recordLength = header.recordLength;
  return LazPointStream::open(path, memory, layout, *header.laz);
}

// 8- or 16-bit colours: the first points tell.
Status LasReader::State::probeColorDepth() {
  LasHeader& h = header;
  rgb = colorOffset(h.pointFormat);
  h.hasColors = rgb != 0;
  if (!h.hasColors || (h.compressed && headerOnly)) return {};
  const std::uint64_t count = std::min<std::uint64_t>(h.pointCount, kColorProbe);
  std::vector<std::byte> probed(count * h.recordLength);
  if (h.compressed) {  // the first batch the reader decodes anyway
    Result<std::span<const std::byte>> ahead = lazPoints->peek();
    if (!ahead) return ahead.status();
    probed.assign(ahead->begin(), ahead->begin() + static_cast<std::ptrdiff_t>(
                                                       std::min(ahead->size(), probed.size())));
  } else {
    Result<ByteSource> probe = reopen();
    if (!probe) return probe.status();
    probe->skip(h.pointOffset);
    if (!probe->read(probed.data(), probed.size())) probed.clear();
  }
  std::uint16_t largest = 0;
  for (std::size_t at = 0; at + h.recordLength <= probed.size(); at += h.recordLength) {
    for (std::size_t c = 0; c < 3; ++c)
      largest = std::max(largest, loadField<std::uint16_t>(probed.data() + at + rgb + 2 * c));
  }
  h.eightBitColors = largest <= 255;
  return {};
}

Result<LasHeader> LasReader::readHeader(const std::string& path) {
  Result<ByteSource> source = ByteSource::openFile(path);
  if (!source) return source.status();
  auto state = std::make_unique<State>();
  state->path = path;
  state->source.emplace(std::move(*source));
  state->headerOnly = true;
  Result<LasReader> reader = start(std::move(state));
  if (!reader) return reader.status();
  return reader->header();
}

Result<LasReader> LasReader::start(std::unique_ptr<State> state) try {
  std::vector<std::byte> bytes;
  LODFORGE_TRY(state->readHeader(bytes));
  LODFORGE_TRY(state->readScalesAndBounds(bytes));
  LODFORGE_TRY(state->checkPointData());
  CrsRecords crs;
  LODFORGE_TRY(state->readRecords(crs));
  LODFORGE_TRY(state->readExtendedRecords(crs));
  state->readExtraBytes();
  state->header.crs = crs.crs();
  LODFORGE_TRY(state->readLazRecord());
  ByteSource& source = *state->source;
  if (!source.skip(state->header.pointOffset - source.offset()))
    return state->fail(source.offset(), "the file ends before the point data");
  LODFORGE_TRY(state->probeColorDepth());
  return LasReader(std::move(state));
} catch (const ErrorException& e) {
  return e.error;
}

Status LasReader::restrictTo(std::uint64_t first, std::uint64_t count) try {
  State& s = *state_;
  const LasHeader& h = s.header;
  assert(s.nextPoint == 0);
  first = std::min(first, h.pointCount);
  if (h.compressed && !s.lazPoints)
    return Error{ErrorKind::kUnsupported,
                 fmt::format("{}: the header alone was read", s.source->name())};
  if (h.compressed) {
    LODFORGE_TRY(s.lazPoints->skipTo(first));
  } else if (!s.source->skip(first * h.recordLength)) {
    return s.fail(s.source->offset(), fmt::format("the file ends before point {}", first));
  }
  s.nextPoint = first;
  s.endPoint = first + std::min(count, h.pointCount - first);
  return {};
} catch (const ErrorException& e) {
  return e.error;
}

Result<bool> LasReader::nextRecords(std::vector<std::byte>& records) try {
  State& s = *state_;
  const LasHeader& h = s.header;
  records.clear();
  const std::uint64_t end = std::min(h.pointCount, s.endPoint);
  if (s.nextPoint >= end) return false;
  const std::size_t count =
      static_cast<std::size_t>(std::min<std::uint64_t>(s.batchSize, end - s.nextPoint));
  records.resize(count * h.recordLength);
  if (s.lazPoints) {
    LODFORGE_TRY(s.lazPoints->read(records.data(), count));
  } else {
    const std::uint64_t at = s.source->offset();
    if (!s.source->read(records.data(), records.size()))
      return s.fail(at, fmt::format("the file ends inside point {}", s.nextPoint));
  }
  s.nextPoint += count;
  return true;
} catch (const ErrorException& e) {
  return e.error;
}

Result<bool> LasReader::next(PointBatch& batch) {
  State& s = *state_;
  const LasHeader& h = s.header;
  batch.clear();
  batch.first = s.nextPoint;
  Result<bool> more = nextRecords(s.records);
  if (!more || !*more) return more;
  const std::size_t count = s.records.size() / h.recordLength;
  batch.positions.resize(count);
  batch.attributes.resize(count);
  if (h.hasColors) batch.colors.resize(count);
  const std::size_t stride = h.extras.stride, extrasAt = lasRecordSize(h.pointFormat);
  batch.extras.resize(count * stride);
  for (std::size_t i = 0; i < count; ++i) {
    const std::byte* r = s.records.data() + i * h.recordLength;
    if (stride != 0) std::memcpy(batch.extras.data() + i * stride, r + extrasAt, stride);
    batch.attributes[i] = recordAttributes(r, h.pointFormat);
    Vec3d& p = batch.positions[i];
    for (int k = 0; k < 3; ++k) {
      // Double precision: scale 0.01 at offset 6e5 keeps the centimetres exactly as written.
      p[k] = static_cast<double>(loadField<std::int32_t>(r + 4 * static_cast<std::size_t>(k))) *
                 h.scale[k] +
             h.offset[k];
    }
    if (h.hasColors) {
      std::uint16_t rgb[3];
      std::memcpy(rgb, r + s.rgb, sizeof rgb);
      const int shift = h.eightBitColors ? 0 : 8;
      batch.colors[i] = {static_cast<std::uint8_t>(std::min(255, rgb[0] >> shift)),
                         static_cast<std::uint8_t>(std::min(255, rgb[1] >> shift)),
                         static_cast<std::uint8_t>(std::min(255, rgb[2] >> shift)), 255};
    }
  }
  return true;
}

}  // namespace lodforge
