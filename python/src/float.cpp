// The bindings in float: the submodule sphere._sphere.float (precision.hpp).
#include "precision.hpp"

namespace sphere_python {

void bind_float(py::module_& m) { bind_precision<float>(m, "float", "sphere in float precision"); }

} // namespace sphere_python
