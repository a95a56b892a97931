#pragma once
// What every source of the extension module shares (docs/python.md): the library, pybind11,
// and the conversions between Python values and the library's vectors, arrays and names.
#include <sphere/dem.cuh>
#include <sphere/io.cuh>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sphere_python {

namespace py = pybind11;

/// A C-contiguous array of doubles, converted by NumPy from whatever the caller passed.
using doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Binds one precision into `m` (float.cpp, double.cpp).
void bind_float(py::module_& m);
void bind_double(py::module_& m);

/// The names of an enumeration's values, in the order of their values (the library's
/// spelling: boundary::wall is "wall").
template <class E>
const std::vector<std::string>& names_of();

template <>
inline const std::vector<std::string>& names_of<sphere::boundary>()
{
    static const std::vector<std::string> names{sphere::name(sphere::boundary::wall),
                                                sphere::name(sphere::boundary::periodic)};
    return names;
}
template <>
inline const std::vector<std::string>& names_of<sphere::wall_mode>()
{
    static const std::vector<std::string> names{sphere::name(sphere::wall_mode::fixed),
                                                sphere::name(sphere::wall_mode::velocity),
                                                sphere::name(sphere::wall_mode::stress)};
    return names;
}
template <>
inline const std::vector<std::string>& names_of<sphere::damping_convention>()
{
    static const std::vector<std::string> names{"absolute", "mass_scaled", "damping_ratio"};
    return names;
}
template <>
inline const std::vector<std::string>& names_of<sphere::pair_summation>()
{
    static const std::vector<std::string> names{"automatic", "slabs", "gather"};
    return names;
}
template <>
inline const std::vector<std::string>& names_of<sphere::motion>()
{
    static const std::vector<std::string> names{"free", "prescribed", "fixed", "prescribed_horizontal"};
    return names;
}

/// The name of an enumeration value.
template <class E>
py::str name_of(E value)
{
    return py::str(names_of<E>().at(static_cast<std::size_t>(value)));
}

/// The value named by a Python string; a sphere::error naming `where` for anything else.
template <class E>
E parse(py::handle value, const std::string& where)
{
    const std::vector<std::string>& names = names_of<E>();
    if (py::isinstance<py::str>(value)) {
        const std::string name = value.cast<std::string>();
        for (std::size_t k = 0; k < names.size(); ++k)
            if (names[k] == name) return static_cast<E>(k);
    }
    std::string choices;
    for (const std::string& n : names) choices += (choices.empty() ? "'" : ", '") + n + "'";
    sphere::detail::fail(where, " = ", py::repr(value).cast<std::string>(), ": not one of ", choices);
}

/// A Python number as a double; a sphere::error naming `where` for anything else.
inline double number(py::handle value, const std::string& where)
{
    try {
        return value.cast<double>();
    } catch (const py::cast_error&) {
        sphere::detail::fail(where, " = ", py::repr(value).cast<std::string>(), ": not a number");
    }
}

/// A sequence of three numbers as a vector.
template <class Real>
sphere::vec3<Real> vector3(py::handle value, const std::string& where)
{
    if (!py::isinstance<py::sequence>(value) || py::len(value) != 3)
        sphere::detail::fail(where, " = ", py::repr(value).cast<std::string>(), ": three numbers (x, y, z) are needed");
    const py::sequence s = py::reinterpret_borrow<py::sequence>(value);
    sphere::vec3<Real> v;
    for (int a = 0; a < 3; ++a) v[a] = Real(number(s[a], where + "[" + std::to_string(a) + "]"));
    return v;
}

/// A vector as a tuple of three Python floats.
template <class Real>
py::tuple tuple3(const sphere::vec3<Real>& v)
{
    return py::make_tuple(double(v.x), double(v.y), double(v.z));
}

/// An (n, 3) NumPy array of the vectors (a copy).
template <class Real>
py::array_t<Real> rows(const std::vector<sphere::vec3<Real>>& v)
{
    py::array_t<Real> out({v.size(), std::size_t(3)});
    auto o = out.template mutable_unchecked<2>();
    for (std::size_t i = 0; i < v.size(); ++i)
        for (int a = 0; a < 3; ++a) o(i, a) = v[i][a];
    return out;
}

/// A one-dimensional NumPy array of the values (a copy).
template <class T>
py::array_t<T> column(const std::vector<T>& v)
{
    return py::array_t<T>(v.size(), v.data());
}

/// An array's shape as Python writes it: "(5, 3)", "(5,)".
inline std::string shape_text(const py::array& a)
{
    std::string shape;
    for (py::ssize_t d = 0; d < a.ndim(); ++d) shape += (d ? ", " : "") + std::to_string(a.shape(d));
    return "(" + shape + (a.ndim() == 1 ? ",)" : ")");
}

/// The number of rows of an (N, 3) array argument `name`; a sphere::error for another shape.
inline std::size_t rows_of(const py::array& a, const char* name)
{
    if (a.ndim() != 2 || a.shape(1) != 3)
        sphere::detail::fail(name, " has shape ", shape_text(a), "; (N, 3) is needed");
    return std::size_t(a.shape(0));
}

/// Refuses an array argument `name` whose shape is not (n, width), or (n,) for width 0.
inline void check_shape(const py::array& a, const char* name, std::size_t n, std::size_t width)
{
    const bool ok = width == 0 ? a.ndim() == 1 && std::size_t(a.shape(0)) == n
                               : a.ndim() == 2 && std::size_t(a.shape(0)) == n && std::size_t(a.shape(1)) == width;
    if (!ok)
        sphere::detail::fail(name, " has shape ", shape_text(a), "; (", n,
                             width ? ", " + std::to_string(width) + ")" : std::string(",)"), " is needed");
}

} // namespace sphere_python
