// Output folders of the commands that write into a folder the user names (clothsim render --out,
// compare --diff, golden check --failures): each is published whole, and an existing folder is
// only ever replaced or removed if an earlier run of the same command wrote it.
#pragma once

#include <filesystem>
#include <functional>
#include <string>

namespace clothsim {

// `dir` as an absolute, lexically normal path without a trailing separator ("out/" and "out/."
// name the folder out). Throws std::runtime_error naming `what` (e.g. "--out") for an empty path or
// the root folder.
std::filesystem::path output_folder_path(const std::filesystem::path& dir, const std::string& what);

// Whether the existing folder `dir` is one the command may replace: empty, or holding the file
// `marker` that the command writes into every folder it publishes.
bool replaceable_folder(const std::filesystem::path& dir, const std::string& marker);

// Publishes `target` whole: `write(staging)` fills a fresh hidden sibling ".<name>.tmp-<pid>"
// (`write` must create the file `marker` in it), which is then renamed to `target`. An existing
// `target` is replaced only once the new folder is complete, and only if it is
// replaceable_folder(target, marker); otherwise std::runtime_error naming `what` and the folder,
// before anything is written. On failure the staging folder and the parent folders this call
// created are removed and the exception is rethrown; an older `target` is left as it was.
void publish_folder(const std::filesystem::path& target, const std::string& marker, const std::string& what,
                    const std::function<void(const std::filesystem::path&)>& write);

// Removes `dir` if it exists and replaceable_folder(dir, marker) (an earlier output of the same
// command that is now out of date); returns whether it removed it. Never removes anything else.
bool remove_replaceable_folder(const std::filesystem::path& dir, const std::string& marker);

}  // namespace clothsim
