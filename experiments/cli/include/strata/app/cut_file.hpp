#pragma once
/// \file cut_file.hpp
/// cut.json: a precomputed cut (strata/hierarchy/precomputed_cut.hpp) as written by
/// `strata precompute` and read by "hierarchy": {"mode": "precomputed", "cut": ...}. The format
/// is documented in the README ("Precomputed cuts").
#include <filesystem>

#include "strata/hierarchy/precomputed_cut.hpp"

namespace strata::app {

/// Reads cut.json; InputErrors name the file and key ("cut.json: windows.0.refined.3: ...").
PrecomputedCut read_cut_file(const std::filesystem::path& file);

/// Writes cut.json atomically (a failed write leaves any earlier file in place).
void write_cut_file(const std::filesystem::path& file, const PrecomputedCut& cut);

}  // namespace strata::app
