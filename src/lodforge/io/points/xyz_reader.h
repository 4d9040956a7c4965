// XYZ / TXT / CSV / PTS point reader: one point per line, `x y z [r g b] [nx ny nz]`, the
// separator (spaces or tabs, comma, semicolon) detected from the first data line. A first line of
// names (x,y,z,red,nx,...) maps the columns; without one, the column count decides: 3 x y z,
// 4 x y z intensity, 6 x y z + colour (all integers, some above 1) or normal, 7 x y z intensity
// r g b (PTS), 9 x y z r g b nx ny nz. A lone count line at the top (PTS) is skipped; `#` and
// `//` lines are comments. Streamed in batches.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "lodforge/core/file.h"
#include "lodforge/core/status.h"
#include "lodforge/io/points/point_batch.h"

namespace lodforge {

struct XyzLayout {
  char separator = ' ';  // ' ' means any run of spaces and tabs
  std::size_t columns = 3;
  int x = 0, y = 1, z = 2;  // column of each coordinate
  int red = -1;             // first of three colour columns, -1 for none
  int normal = -1;          // first of three normal columns, -1 for none
  bool unitColors = false;  // colours as 0–1 floats rather than 0–255
  bool hasHeader = false;   // a line of column names came first
};

class XyzReader {
 public:
  static Result<XyzReader> open(const std::string& path, std::size_t batchSize = 1 << 16);
  static Result<XyzReader> fromMemory(std::span<const std::byte> bytes, std::string name,
                                      std::size_t batchSize = 1 << 16);
  XyzReader(XyzReader&&) noexcept;
  XyzReader& operator=(XyzReader&&) noexcept;
  ~XyzReader();

  const XyzLayout& layout() const;
  Result<bool> next(PointBatch& batch);

 private:
  struct State;
  explicit XyzReader(std::unique_ptr<State> state);
  static Result<XyzReader> start(std::unique_ptr<State> state);
  std::unique_ptr<State> state_;
};

}  // namespace lodforge
