#pragma once
/// \file
/// What a path names, when it is not a regular file: the input files efdem reads (the scene, a
/// checkpoint) must be regular files, and a message should say what the path is instead ("not
/// found" for a directory or a FIFO sends the user looking in the wrong place; opening a FIFO
/// blocks until someone writes to it, and /dev/zero never ends).

#include <filesystem>
#include <string>

namespace efdem {

/// Empty if `path` is (or links to) a regular file; else what it is, as the end of a sentence
/// starting with the path: "file not found", "is a directory, not a file", "is a FIFO (named
/// pipe), not a file", "is a device, not a file", "is a socket, not a file", "is a symbolic link
/// that loops", "is a symbolic link to 'x', which does not exist", "cannot be reached: <reason>".
std::string not_a_regular_file(const std::filesystem::path& path);

}  // namespace efdem
