// The bindings in double: the submodule sphere._sphere.double (precision.hpp).
#include "precision.hpp"

namespace sphere_python {

void bind_double(py::module_& m) { bind_precision<double>(m, "double", "sphere in double precision"); }

} // namespace sphere_python
