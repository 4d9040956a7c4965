// A model's texture images written beside a file format that names them rather than holds them
// (OBJ's material library, PLY's TextureFile comments): "<stem>_texture<i>.<ext>" next to the
// model, the image's own bytes. Every side file is checked before any is written: a file of
// that name is replaced only when it already holds the same bytes (a second run); anything
// else there is refused, never overwritten, and nothing is written.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "lodforge/core/model.h"
#include "lodforge/core/status.h"

namespace lodforge {

class SideFiles {
 public:
  void add(std::string path, std::string bytes) {
    files_.emplace_back(std::move(path), std::move(bytes));
  }
  // Checks every file, then writes those not already there with the same bytes.
  Status writeAll() const;

 private:
  std::vector<std::pair<std::string, std::string>> files_;
};

// The model's images, in its order, as side files of the model at `path`; their names
// (relative to the model's folder).
Result<std::vector<std::string>> addImagesBeside(const Model& model, const std::string& path,
                                                 SideFiles& files);

}  // namespace lodforge
