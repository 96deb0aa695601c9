#include "scene_implicit.hpp"

#include <string>
#include <vector>

namespace strata::app::detail {
namespace {

std::vector<ImplicitShape> parse_operands(const SceneValue& value, const std::string& kind) {
  const std::vector<SceneValue> elements = value.elements();
  if (kind == "difference" && elements.size() != 2) {
    value.fail("must list exactly 2 shapes (the first minus the second), got " +
               std::to_string(elements.size()));
  }
  if (elements.empty()) value.fail("must list at least 1 shape");
  std::vector<ImplicitShape> operands;
  for (const SceneValue& element : elements)
    operands.push_back(parse_implicit_shape(element));
  return operands;
}

}  // namespace

ImplicitShape parse_implicit_shape(const SceneValue& value) {
  value.expect_object({"sphere", "box", "capsule", "torus", "union", "intersection", "difference"});
  const int kinds = value.has("sphere") + value.has("box") + value.has("capsule") +
                    value.has("torus") + value.has("union") + value.has("intersection") +
                    value.has("difference");
  if (kinds != 1) {
    value.fail(
        "must have exactly one of sphere, box, capsule, torus, union, intersection, difference");
  }
  if (value.has("sphere")) {
    const SceneValue sphere = value.at("sphere");
    sphere.expect_object({"center", "radius"});
    return ImplicitShape::sphere(sphere.at("center").vec3(), sphere.at("radius").positive());
  }
  if (value.has("box")) {
    const SceneValue box = value.at("box");
    box.expect_object({"min", "max"});
    const Vector3d min = box.at("min").vec3();
    const Vector3d max = box.at("max").vec3();
    if ((min.array() >= max.array()).any()) box.at("max").fail("must be > min in every coordinate");
    return ImplicitShape::box(min, max);
  }
  if (value.has("capsule")) {
    const SceneValue capsule = value.at("capsule");
    capsule.expect_object({"a", "b", "radius"});
    return ImplicitShape::capsule(capsule.at("a").vec3(), capsule.at("b").vec3(),
                                  capsule.at("radius").positive());
  }
  if (value.has("torus")) {
    const SceneValue torus = value.at("torus");
    torus.expect_object({"center", "axis", "major_radius", "minor_radius"});
    const Vector3d axis =
        torus.has("axis") ? torus.at("axis").nonzero_vec3().normalized() : Vector3d::UnitZ();
    const double major_radius = torus.at("major_radius").positive();
    const double minor_radius = torus.at("minor_radius").positive();
    return ImplicitShape::torus(torus.at("center").vec3(), axis, major_radius, minor_radius);
  }
  if (value.has("union")) {
    return ImplicitShape::csg(ImplicitShape::Kind::union_of,
                              parse_operands(value.at("union"), "union"));
  }
  if (value.has("intersection")) {
    return ImplicitShape::csg(ImplicitShape::Kind::intersection,
                              parse_operands(value.at("intersection"), "intersection"));
  }
  return ImplicitShape::csg(ImplicitShape::Kind::difference,
                            parse_operands(value.at("difference"), "difference"));
}

}  // namespace strata::app::detail
