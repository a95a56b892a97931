#pragma once
/// \file
/// Small fixed-size vectors with host-device operators.
#include <cmath>

#include "config.cuh"
#include "constants.cuh"

namespace sphere {

/// A 3-vector of `Real` (float or double).
template <class Real>
struct vec3 {
    Real x, y, z;

    SPHERE_HDI Real& operator[](int a) { return a == 0 ? x : (a == 1 ? y : z); }
    SPHERE_HDI Real operator[](int a) const { return a == 0 ? x : (a == 1 ? y : z); }

    SPHERE_HDI vec3& operator+=(const vec3& b) { x += b.x; y += b.y; z += b.z; return *this; }
    SPHERE_HDI vec3& operator-=(const vec3& b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
    SPHERE_HDI vec3& operator*=(Real s) { x *= s; y *= s; z *= s; return *this; }
};

/// Component a (0, 1 or 2) of v, by selects. Kernels index vectors with a run-time axis this
/// way (or through the const operator[]): the reference that the non-const operator[] returns
/// makes nvcc keep the vector, and often the kernel's whole parameter block, in local memory.
template <class Real>
SPHERE_HDI Real component(const vec3<Real>& v, int a)
{
    return a == 0 ? v.x : (a == 1 ? v.y : v.z);
}

/// The vector with s on axis a (0, 1 or 2) and zeros on the others.
template <class Real>
SPHERE_HDI vec3<Real> along_axis(int a, Real s)
{
    return {a == 0 ? s : Real(0), a == 1 ? s : Real(0), a == 2 ? s : Real(0)};
}

/// Position and radius packed 4-wide (x, y, z, r) so that one aligned load reads both.
template <class Real>
struct alignas(4 * sizeof(Real)) vec4 {
    Real x, y, z, w;
    SPHERE_HDI vec3<Real> xyz() const { return {x, y, z}; }
};

// Operands by reference and results built by component: a vec3<float> copied whole is loaded
// by clang as two floats in one vector and a third, which its loop vectoriser refuses.
template <class Real> SPHERE_HDI vec3<Real> operator+(const vec3<Real>& a, const vec3<Real>& b)
{
    return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class Real> SPHERE_HDI vec3<Real> operator-(const vec3<Real>& a, const vec3<Real>& b)
{
    return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class Real> SPHERE_HDI vec3<Real> operator-(const vec3<Real>& a) { return {-a.x, -a.y, -a.z}; }
template <class Real> SPHERE_HDI vec3<Real> operator*(const vec3<Real>& a, Real s) { return {a.x * s, a.y * s, a.z * s}; }
template <class Real> SPHERE_HDI vec3<Real> operator*(Real s, const vec3<Real>& a) { return {a.x * s, a.y * s, a.z * s}; }
template <class Real> SPHERE_HDI vec3<Real> operator/(const vec3<Real>& a, Real s) { return {a.x / s, a.y / s, a.z / s}; }
template <class Real> SPHERE_HDI bool operator==(const vec3<Real>& a, const vec3<Real>& b)
{
    return a.x == b.x && a.y == b.y && a.z == b.z;
}

template <class Real> SPHERE_HDI Real dot(const vec3<Real>& a, const vec3<Real>& b)
{
    return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class Real> SPHERE_HDI vec3<Real> cross(const vec3<Real>& a, const vec3<Real>& b)
{
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class Real> SPHERE_HDI Real norm2(const vec3<Real>& a) { return dot(a, a); }
template <class Real> SPHERE_HDI Real norm(const vec3<Real>& a) { return std::sqrt(dot(a, a)); }

/// c ? a : b, component by component: unlike the conditional operator on whole vectors
/// (a conditional copy in memory), a select that a loop over contacts can vectorise.
template <class Real> SPHERE_HDI vec3<Real> select(bool c, const vec3<Real>& a, const vec3<Real>& b)
{
    return {c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z};
}
template <class Real> SPHERE_HDI vec4<Real> select(bool c, const vec4<Real>& a, const vec4<Real>& b)
{
    return {c ? a.x : b.x, c ? a.y : b.y, c ? a.z : b.z, c ? a.w : b.w};
}

/// Whether every component is finite; without branches (|c| <= max is false for inf and NaN).
template <class Real> SPHERE_HDI bool isfinite(const vec3<Real>& a)
{
    const Real big = largest<Real>;
    const bool x = std::fabs(a.x) <= big, y = std::fabs(a.y) <= big, z = std::fabs(a.z) <= big;
    return x & y & z;
}

/// Converts between precisions (e.g. a double vector from user input to the simulation's Real).
template <class To, class From> SPHERE_HDI vec3<To> vec_cast(const vec3<From>& a)
{
    return {static_cast<To>(a.x), static_cast<To>(a.y), static_cast<To>(a.z)};
}
template <class To, class From> SPHERE_HDI vec4<To> vec_cast(const vec4<From>& a)
{
    return {static_cast<To>(a.x), static_cast<To>(a.y), static_cast<To>(a.z), static_cast<To>(a.w)};
}

} // namespace sphere
