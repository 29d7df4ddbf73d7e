// Each shape family declared once: its name, what it is, what exact body it
// is the smooth form of, its frame's axes, and its parameters (key, meaning,
// admissible range, default, power of length, an example value).
//
// Everything that names a family's parameters reads this table: the
// constructors' validation (shapes.cpp: "field 'R' must be finite and > 0"),
// describe(), num_params / param_names / shape_params / param_length_powers /
// shape_with_params (shape_params.hpp), the scene reader and
// `idcol_harness shapes` (harness/src/scene/scene.cpp), and the Python
// classes' properties, docstrings, repr and pickling (core/python). The
// solver never reads it: it is not on the solve path.
//
// A scalar family (every family but the smooth polytope) also gives its
// parameters as an array and its constructor from one (FamilyParams<T>
// below); the smooth polytope's inputs are arrays of half-spaces or
// vertices, which its own code reads.
#pragma once

#include <array>
#include <cstddef>
#include <type_traits>
#include <variant>
#include <vector>

#include "idcol/shapes.hpp"

namespace idcol {

/// One parameter as the family's constructor takes it.
struct FamilyParam {
  const char* key;      ///< the constructor's argument, the scene's key, Python's keyword, param_names' entry
  const char* meaning;  ///< what it is, with its units
  double lower;         ///< the least admissible value ...
  bool lower_open;      ///< ... excluded (value > lower) or not (value >= lower); every value is also finite
  double fallback;      ///< its value where it is omitted; NaN: required
  int length_power;     ///< 1 for a length, 0 for a dimensionless number (param_length_powers)
  double example;       ///< the catalogue's example value
  bool array;           ///< an array input (the polytope's normals, offsets, vertices), not a scalar
};

/// One family.
struct FamilyInfo {
  const char* name;            ///< the scene's `family`, family_name(), the class's kName
  const char* type;            ///< the C++ class and the Python class
  const char* summary;         ///< what the body is: phi(y) <= 0
  const char* smooth_form_of;  ///< the exact body it smooths, and in which limit ("" where it is exact)
  const char* axes;            ///< the body's frame: its axis, or what its parameters lie along
  std::vector<FamilyParam> params;
  /// The scalar parameters (array == false), in the constructor's order.
  std::vector<const FamilyParam*> scalars() const;
};

/// Every family, in the order of Shape's alternatives (Shape::index()).
const std::vector<FamilyInfo>& shape_families();
/// The family of s.
const FamilyInfo& family_info(const Shape& s);

namespace detail {
template <class T, class V>
struct AlternativeIndex;
template <class T, class... A>
struct AlternativeIndex<T, std::variant<A...>> {
  static constexpr std::size_t value = [] {
    constexpr bool same[] = {std::is_same_v<T, A>...};
    for (std::size_t i = 0; i < sizeof...(A); ++i)
      if (same[i]) return i;
    return sizeof...(A);
  }();
};
}  // namespace detail

/// The family of the class T.
template <class T>
const FamilyInfo& family_info() {
  constexpr std::size_t i = detail::AlternativeIndex<T, Shape>::value;
  static_assert(i < std::variant_size_v<Shape>, "T is one of Shape's alternatives");
  return shape_families()[i];
}

/// Throws std::invalid_argument "FAMILY: field 'KEY' must be finite and > 0,
/// got V" (or ">= LOWER") unless v lies in p's range; a subnormal length is
/// refused too (every length the solver forms from it would round to
/// nothing).
void check_param(const char* family, const FamilyParam& p, double v);

/// A scalar family's parameters as an array, in family_info<T>()'s order,
/// and its constructor from one. The polytope has none: its inputs are
/// arrays.
template <class T>
struct FamilyParams;
template <>
struct FamilyParams<Sphere> {
  static constexpr int kCount = 1;
  static std::array<double, 1> get(const Sphere& s) { return {s.R()}; }
  static Sphere make(const double* t) { return Sphere(t[0]); }
};
template <>
struct FamilyParams<Superellipsoid> {
  static constexpr int kCount = 4;
  static std::array<double, 4> get(const Superellipsoid& s) { return {s.a(), s.b(), s.c(), s.n()}; }
  static Superellipsoid make(const double* t) { return Superellipsoid(t[0], t[1], t[2], t[3]); }
};
template <>
struct FamilyParams<SuperellipticCylinder> {
  static constexpr int kCount = 3;
  static std::array<double, 3> get(const SuperellipticCylinder& s) { return {s.R(), s.h(), s.n()}; }
  static SuperellipticCylinder make(const double* t) { return SuperellipticCylinder(t[0], t[1], t[2]); }
};
template <>
struct FamilyParams<SmoothTruncatedCone> {
  static constexpr int kCount = 5;
  static std::array<double, 5> get(const SmoothTruncatedCone& s) { return {s.Rb(), s.Rt(), s.a(), s.b(), s.beta()}; }
  static SmoothTruncatedCone make(const double* t) { return SmoothTruncatedCone(t[0], t[1], t[2], t[3], t[4]); }
};

/// Whether T's parameters are scalars (FamilyParams<T> exists).
template <class T>
inline constexpr bool kScalarFamily = !std::is_same_v<T, SmoothPolytope>;

/// The shape of scalar family f with parameters theta (f's scalars, in
/// order), through its constructor: it validates and throws
/// std::invalid_argument naming the field and value. Throws
/// std::invalid_argument for the smooth polytope, whose inputs are arrays.
Shape scalar_family_shape(const FamilyInfo& f, const double* theta);

}  // namespace idcol
