// The bindings in float: the submodule sphere._sphere.float (one translation unit per precision,
// so that the two compile in parallel).
#include "analysis.hpp"
#include "experiments.hpp"
#include "setup.hpp"
#include "simulation.hpp"

namespace sphere_python {

void bind_float(py::module_& m)
{
    py::module_ sub = m.def_submodule("float", "sphere in float precision");
    bind_simulation<float>(sub);
    bind_setup<float>(sub);
    bind_experiments<float>(sub);
    bind_analysis<float>(sub);
}

} // namespace sphere_python
