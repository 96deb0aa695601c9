#include "scene_hierarchy.hpp"

#include <memory>

#include "strata/app/cut_file.hpp"
#include "strata/core/common/error.hpp"
#include "strata/hierarchy/refinement_indicator_registry.hpp"

namespace strata::app::detail {

HierarchySettings parse_hierarchy(const SceneValue& value, const std::filesystem::path& folder) {
  // clang-format off
  value.expect_object({"levels", "mode", "level", "adapt_every", "max_passes", "indicator",
                       "refine_threshold", "coarsen_tolerance", "coarsen_indicator_fraction",
                       "stress_floor", "min_steps_between_changes", "max_active_elements",
                       "max_level", "balance", "tolerance", "initial_adaptation",
                       "in_step_refinement", "full_resolution_fraction", "coarsen_budget", "cut",
                       "finest_contact_points"});
  // clang-format on
  HierarchySettings settings;
  settings.levels = value.at("levels").integer(0);
  if (settings.levels > 8) value.at("levels").fail("must be at most 8");
  if (value.has("mode")) {
    settings.mode = static_cast<HierarchyMode>(
        value.at("mode").choice({"full", "uniform", "adaptive", "precomputed"}));
  }
  if (settings.mode == HierarchyMode::precomputed) {
    if (!value.has("cut")) value.fail("mode \"precomputed\" needs \"cut\" (a cut.json file)");
    const std::string name = value.at("cut").string();
    if (name.empty()) value.at("cut").fail("must not be empty");
    std::filesystem::path path(name);
    if (!path.is_absolute()) path = folder / path;
    try {
      settings.precomputed = std::make_shared<const PrecomputedCut>(read_cut_file(path));
    } catch (const InputError& error) {
      value.at("cut").fail(error.what());
    }
    if (settings.precomputed->levels != settings.levels) {
      value.at("levels").fail("is " + std::to_string(settings.levels) + ", and the cut '" + name +
                              "' was recorded with " +
                              std::to_string(settings.precomputed->levels) +
                              " levels (a cut belongs to one tree)");
    }
  } else if (value.has("cut") && settings.mode != HierarchyMode::full) {
    // Mode full (a precomputed scene's full-resolution reference) ignores it with a warning.
    value.at("cut").fail("only with mode \"precomputed\"");
  }
  if (value.has("level")) {
    settings.level = value.at("level").integer(0);
    if (settings.level > settings.levels) value.at("level").fail("must be at most levels");
  } else if (settings.mode == HierarchyMode::uniform) {
    value.fail("mode \"uniform\" needs \"level\"");
  }
  if (value.has("adapt_every")) settings.adapt_every = value.at("adapt_every").integer(1);
  if (value.has("max_passes")) settings.max_passes = value.at("max_passes").integer(1);
  if (value.has("indicator")) {
    const std::vector<std::string> names = refinement_indicator_names();
    settings.indicator = names[value.at("indicator").choice(names)];
  }
  if (value.has("tolerance")) {
    settings.tolerance = value.at("tolerance").positive();
    if (settings.tolerance >= 1.0) value.at("tolerance").fail("must be in (0, 1)");
  }
  if (value.has("initial_adaptation"))
    settings.initial_adaptation = value.at("initial_adaptation").boolean();
  if (value.has("in_step_refinement"))
    settings.in_step_refinement = value.at("in_step_refinement").boolean();
  if (value.has("finest_contact_points"))
    settings.finest_contact_points = value.at("finest_contact_points").boolean();
  if (value.has("full_resolution_fraction")) {
    settings.full_resolution_fraction = value.at("full_resolution_fraction").positive();
    if (settings.full_resolution_fraction > 1.0)
      value.at("full_resolution_fraction").fail("must be in (0, 1]");
  }
  if (value.has("coarsen_budget")) {
    settings.coarsen_budget = value.at("coarsen_budget").positive();
    if (settings.coarsen_budget > 1.0) value.at("coarsen_budget").fail("must be in (0, 1]");
  }
  RefinementSettings& criteria = settings.criteria;
  if (value.has("refine_threshold")) {
    criteria.refine_threshold = value.at("refine_threshold").positive();
    settings.refine_threshold_set = true;
  }
  if (value.has("coarsen_tolerance"))
    criteria.coarsen_tolerance = value.at("coarsen_tolerance").positive();
  if (value.has("coarsen_indicator_fraction")) {
    criteria.coarsen_indicator_fraction = value.at("coarsen_indicator_fraction").positive();
    if (criteria.coarsen_indicator_fraction > 1.0)
      value.at("coarsen_indicator_fraction").fail("must be in (0, 1]");
  }
  if (value.has("stress_floor")) criteria.stress_floor = value.at("stress_floor").positive();
  if (value.has("min_steps_between_changes"))
    criteria.min_steps_between_changes = value.at("min_steps_between_changes").integer(0);
  if (value.has("max_active_elements"))
    criteria.max_active_elements = value.at("max_active_elements").integer(0);
  if (value.has("max_level")) {
    criteria.max_level = value.at("max_level").integer(0);
    if (criteria.max_level > settings.levels) value.at("max_level").fail("must be at most levels");
    if (settings.mode == HierarchyMode::adaptive && value.has("level") &&
        settings.level > criteria.max_level)
      value.at("level").fail("is " + std::to_string(settings.level) + ", deeper than max_level " +
                             std::to_string(criteria.max_level) +
                             " (the cut starts where refinement may not reach)");
  }
  if (value.has("balance")) criteria.balance = value.at("balance").boolean();
  try {
    validate_hierarchy_settings(settings, value.path());
  } catch (const InputError& error) {
    value.fail(error.what());
  }
  return settings;
}

}  // namespace strata::app::detail
