#pragma once
/// \file refinement_indicator_registry.hpp
/// The refinement indicators strata ships, one traits entry each. The entries drive the scene
/// file's names (`hierarchy.indicator`), the construction of a run's indicator and its checks.
///
/// Adding an indicator: a RefinementIndicator subclass in its own header and source, and one entry
/// in refinement_indicator_registry.cpp.
#include <memory>
#include <string>
#include <vector>

#include "strata/hierarchy/refinement_controller.hpp"
#include "strata/hierarchy/refinement_indicator.hpp"

namespace strata {

struct RefinementIndicatorTraits {
  std::string name;     ///< scene-file name
  std::string summary;  ///< one line: what η measures
  /// η is the tet's share of the run's estimated error: the refine threshold defaults to 1 and a
  /// run refines only while its estimate exceeds the tolerance.
  bool estimates_error;
  /// The indicator for a run with tolerance τ and these criteria.
  std::unique_ptr<RefinementIndicator> (*make)(double tolerance,
                                               const RefinementSettings& criteria);
};

/// Every indicator; the first is the default.
const std::vector<RefinementIndicatorTraits>& refinement_indicator_registry();

/// The entry named `name`; throws InputError naming `where` and listing the registered names.
const RefinementIndicatorTraits& refinement_indicator_traits(const std::string& name,
                                                             const std::string& where);

/// The registered names, in registry order.
std::vector<std::string> refinement_indicator_names();

}  // namespace strata
