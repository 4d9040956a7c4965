#include "lodforge/io/points/las_copy.h"

#include <cstring>
#include <vector>

#include "lodforge/core/file.h"
#include "lodforge/core/progress.h"
#include "lodforge/io/points/las_format.h"
#include "lodforge/io/points/las_reader.h"
#include "lodforge/io/points/record_field.h"

namespace lodforge {

namespace {

using las::kEvlrHeader, las::kVlrHeader;

// Records of compressed layouts: LASzip's, and COPC's info and hierarchy.
bool describesCompression(const std::byte* recordHeader) {
  const std::string user = loadText(recordHeader + 2, 16);
  return user == "laszip encoded" || user == "copc";
}

template <class T>
void storeField(std::vector<std::byte>& bytes, std::size_t at, T value) {
  std::memcpy(bytes.data() + at, &value, sizeof value);
}

struct Sections {
  std::vector<std::byte> header, vlrs, evlrs;
  std::uint32_t vlrCount = 0, evlrCount = 0;
};

// The header, the VLRs (and any bytes between them and the points) and the EVLRs, the compression
// records left out.
Result<Sections> readSections(const std::string& input, const LasHeader& h,
                              LasCopyReport& report) try {
  Result<ByteSource> in = ByteSource::openFile(input);
  if (!in) return in.status();
  Sections s;
  s.header.resize(h.headerSize);
  in->read(s.header.data(), s.header.size());
  std::vector<std::byte> record;
  for (std::uint32_t v = 0; v < h.vlrCount; ++v) {  // the reader has checked their bounds
    record.resize(kVlrHeader);
    in->read(record.data(), kVlrHeader);
    record.resize(kVlrHeader + loadField<std::uint16_t>(record.data() + 20));
    in->read(record.data() + kVlrHeader, record.size() - kVlrHeader);
    if (describesCompression(record.data())) {
      ++report.recordsDropped;
      continue;
    }
    s.vlrs.insert(s.vlrs.end(), record.begin(), record.end());
    ++s.vlrCount;
  }
  const std::uint64_t padding = h.pointOffset - in->offset();
  record.resize(padding);
  in->read(record.data(), padding);
  s.vlrs.insert(s.vlrs.end(), record.begin(), record.end());
  if (h.versionMinor < 4) return s;
  const auto evlrOffset = loadField<std::uint64_t>(s.header.data() + 235);
  const auto evlrCount = loadField<std::uint32_t>(s.header.data() + 243);
  if (evlrCount == 0 || !in->skip(evlrOffset - in->offset())) return s;
  for (std::uint32_t v = 0; v < evlrCount; ++v) {
    record.resize(kEvlrHeader);
    if (!in->read(record.data(), kEvlrHeader)) break;
    const auto length = loadField<std::uint64_t>(record.data() + 20);
    if (length > in->remaining())
      return badInputAtByte(input, in->offset() - kEvlrHeader + 20,
                            "an extended record runs past the end of the file");
    if (describesCompression(record.data())) {
      in->skip(length);
      ++report.recordsDropped;
      continue;
    }
    record.resize(kEvlrHeader + length);
    in->read(record.data() + kEvlrHeader, length);
    s.evlrs.insert(s.evlrs.end(), record.begin(), record.end());
    ++s.evlrCount;
  }
  return s;
} catch (const ErrorException& e) {
  return e.error;
}

// The header as the plain file has it: uncompressed format, new offsets and counts.
void rewriteHeader(Sections& s, const LasHeader& h) {
  storeField<std::uint8_t>(s.header, 104, static_cast<std::uint8_t>(h.pointFormat));
  const auto pointOffset = static_cast<std::uint32_t>(s.header.size() + s.vlrs.size());
  storeField<std::uint32_t>(s.header, 96, pointOffset);
  storeField<std::uint32_t>(s.header, 100, s.vlrCount);
  if (h.versionMinor < 4) return;
  const std::uint64_t evlrOffset =
      s.evlrCount > 0 ? pointOffset + h.pointCount * h.recordLength : 0;
  storeField<std::uint64_t>(s.header, 235, evlrOffset);
  storeField<std::uint32_t>(s.header, 243, s.evlrCount);
}

}  // namespace

Result<LasCopyReport> writeUncompressedLas(const std::string& input, const std::string& output) {
  Result<LasReader> reader = LasReader::open(input);
  if (!reader) return reader.status();
  const LasHeader& h = reader->header();
  LasCopyReport report;
  Result<Sections> sections = readSections(input, h, report);
  if (!sections) return sections.status();
  report.recordsKept = sections->vlrCount + sections->evlrCount;
  rewriteHeader(*sections, h);
  Result<OutputFile> out = OutputFile::create(output);
  if (!out) return out.status();
  LODFORGE_TRY(out->writeSpan<std::byte>(sections->header));
  LODFORGE_TRY(out->writeSpan<std::byte>(sections->vlrs));
  Progress progress("decoding points", h.pointCount);
  std::vector<std::byte> records;
  while (true) {
    Result<bool> more = reader->nextRecords(records);
    if (!more) return more.status();
    if (!*more) break;
    LODFORGE_TRY(out->writeSpan<std::byte>(records));
    report.points += records.size() / h.recordLength;
    progress.advance(records.size() / h.recordLength);
    LODFORGE_TRY(checkCancelled());
  }
  progress.finish();
  LODFORGE_TRY(out->writeSpan<std::byte>(sections->evlrs));
  LODFORGE_TRY(out->commit());
  return report;
}

}  // namespace lodforge
