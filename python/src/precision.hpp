#pragma once
// Everything bound in one precision, as the submodule sphere._sphere.<name> (float.cpp and
// double.cpp each bind one, so that the two compile in parallel).
#include "analysis.hpp"
#include "experiments.hpp"
#include "fluid.hpp"
#include "setup.hpp"
#include "simulation.hpp"

namespace sphere_python {

template <class Real>
void bind_precision(py::module_& m, const char* name, const char* doc)
{
    py::module_ sub = m.def_submodule(name, doc);
    bind_simulation<Real>(sub);
    bind_setup<Real>(sub);
    bind_experiments<Real>(sub);
    bind_analysis<Real>(sub);
    bind_fluid<Real>(sub);
}

} // namespace sphere_python
