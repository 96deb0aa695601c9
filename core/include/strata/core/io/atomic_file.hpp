#pragma once
/// \file atomic_file.hpp
/// Crash-safe file writing: a reader never sees a half-written file.
#include <filesystem>
#include <functional>
#include <ostream>

namespace strata {

/// Writes a file through `write`, atomically replacing `path`.
///
/// The content goes to a temporary file in the same folder (so the final rename stays on one file
/// system); it is flushed, synced and its stream state checked, then renamed over `path`. If
/// `write` throws, or anything fails, the temporary file is removed and `path` keeps its previous
/// content. Errors of the writing itself are InputError naming `path`; an exception thrown by
/// `write` is rethrown unchanged.
void write_file_atomically(const std::filesystem::path& path,
                           const std::function<void(std::ostream&)>& write);

}  // namespace strata
