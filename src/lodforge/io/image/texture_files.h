// Where a texture a model names lies: relative to the model (or its material library), with
// Windows separators taken as folders, and a path from another machine ("C:\Users\…\a.jpg",
// "/home/…/a.jpg") or a name in another case ("TEST.PNG" for test.png, as Windows exports have
// it) looked for beside the model by its file name.
#pragma once

#include <string>
#include <vector>

namespace lodforge {

// The texture's file, or empty when it is nowhere. `directories` end with '/'; `guessed` is set
// when only the file name matched (the caller warns).
std::string findTextureFile(const std::string& name, const std::vector<std::string>& directories,
                            bool& guessed);

}  // namespace lodforge
