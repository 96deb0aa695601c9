#include "strata/meshing/implicit_shape.hpp"

#include <sstream>

#include "strata/core/common/error.hpp"

namespace strata {
namespace {

const char* kind_name(ImplicitShape::Kind kind) {
  switch (kind) {
    case ImplicitShape::Kind::sphere:
      return "sphere";
    case ImplicitShape::Kind::box:
      return "box";
    case ImplicitShape::Kind::capsule:
      return "capsule";
    case ImplicitShape::Kind::torus:
      return "torus";
    case ImplicitShape::Kind::union_of:
      return "union";
    case ImplicitShape::Kind::intersection:
      return "intersection";
    case ImplicitShape::Kind::difference:
      return "difference";
  }
  return "?";
}

bool is_csg(ImplicitShape::Kind kind) {
  return kind == ImplicitShape::Kind::union_of || kind == ImplicitShape::Kind::intersection ||
         kind == ImplicitShape::Kind::difference;
}

void write_vector(std::ostream& out, const Vector3d& v) {
  out << '[' << v.x() << ',' << v.y() << ',' << v.z() << ']';
}

void describe(std::ostream& out, const ImplicitShape& shape) {
  out << kind_name(shape.kind) << '(';
  switch (shape.kind) {
    case ImplicitShape::Kind::sphere:
      write_vector(out, shape.center);
      out << ',' << shape.radius;
      break;
    case ImplicitShape::Kind::box:
      write_vector(out, shape.min);
      out << ',';
      write_vector(out, shape.max);
      break;
    case ImplicitShape::Kind::capsule:
      write_vector(out, shape.a);
      out << ',';
      write_vector(out, shape.b);
      out << ',' << shape.radius;
      break;
    case ImplicitShape::Kind::torus:
      write_vector(out, shape.center);
      out << ',';
      write_vector(out, shape.axis);
      out << ',' << shape.major_radius << ',' << shape.minor_radius;
      break;
    default:
      for (std::size_t i = 0; i < shape.operands.size(); ++i) {
        if (i > 0) out << ',';
        describe(out, shape.operands[i]);
      }
  }
  out << ')';
}

}  // namespace

ImplicitShape ImplicitShape::sphere(const Vector3d& center, double radius) {
  ImplicitShape shape;
  shape.kind = Kind::sphere;
  shape.center = center;
  shape.radius = radius;
  return shape;
}

ImplicitShape ImplicitShape::box(const Vector3d& min, const Vector3d& max) {
  ImplicitShape shape;
  shape.kind = Kind::box;
  shape.min = min;
  shape.max = max;
  return shape;
}

ImplicitShape ImplicitShape::capsule(const Vector3d& a, const Vector3d& b, double radius) {
  ImplicitShape shape;
  shape.kind = Kind::capsule;
  shape.a = a;
  shape.b = b;
  shape.radius = radius;
  return shape;
}

ImplicitShape ImplicitShape::torus(const Vector3d& center, const Vector3d& axis,
                                   double major_radius, double minor_radius) {
  ImplicitShape shape;
  shape.kind = Kind::torus;
  shape.center = center;
  shape.axis = axis;
  shape.major_radius = major_radius;
  shape.minor_radius = minor_radius;
  return shape;
}

ImplicitShape ImplicitShape::csg(Kind kind, std::vector<ImplicitShape> operands) {
  ImplicitShape shape;
  shape.kind = kind;
  shape.operands = std::move(operands);
  return shape;
}

LevelSet implicit_shape_level_set(const ImplicitShape& shape, const LevelSetOptions& options) {
  switch (shape.kind) {
    case ImplicitShape::Kind::sphere:
      return level_set_sphere(shape.center, shape.radius, options);
    case ImplicitShape::Kind::box:
      return level_set_box(shape.min, shape.max, options);
    case ImplicitShape::Kind::capsule:
      return level_set_capsule(shape.a, shape.b, shape.radius, options);
    case ImplicitShape::Kind::torus:
      return level_set_torus(shape.center, shape.axis, shape.major_radius, shape.minor_radius,
                             options);
    default:
      break;
  }
  const std::string name = kind_name(shape.kind);
  if (!is_csg(shape.kind)) throw InputError("implicit shape: unknown kind");
  if (shape.operands.empty()) throw InputError("implicit " + name + ": needs at least 1 operand");
  if (shape.kind == ImplicitShape::Kind::difference && shape.operands.size() != 2) {
    throw InputError("implicit difference: needs exactly 2 operands, got " +
                     std::to_string(shape.operands.size()));
  }
  LevelSet result = implicit_shape_level_set(shape.operands.front(), options);
  for (std::size_t i = 1; i < shape.operands.size(); ++i) {
    const LevelSet operand = implicit_shape_level_set(shape.operands[i], options);
    if (shape.kind == ImplicitShape::Kind::union_of)
      result = csg_union(result, operand);
    else if (shape.kind == ImplicitShape::Kind::intersection)
      result = csg_intersection(result, operand);
    else
      result = csg_difference(result, operand);
  }
  return result;
}

std::string describe_implicit_shape(const ImplicitShape& shape) {
  std::ostringstream out;
  out.precision(17);
  describe(out, shape);
  return out.str();
}

}  // namespace strata
