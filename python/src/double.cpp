// The bindings in double: the submodule sphere._sphere.double (one translation unit per precision,
// so that the two compile in parallel).
#include "analysis.hpp"
#include "experiments.hpp"
#include "setup.hpp"
#include "simulation.hpp"

namespace sphere_python {

void bind_double(py::module_& m)
{
    py::module_ sub = m.def_submodule("double", "sphere in double precision");
    bind_simulation<double>(sub);
    bind_setup<double>(sub);
    bind_experiments<double>(sub);
    bind_analysis<double>(sub);
}

} // namespace sphere_python
