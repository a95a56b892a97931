#pragma once
/// \file
/// Execution policies: tag types that select where kernels run.

namespace sphere {

/// Kernels run on CPU threads through OpenMP; sorting through Thrust's OpenMP system.
/// Every test runs on this backend.
struct host {};

/// Kernels run on an NVIDIA GPU; sorting and reductions through Thrust/CUB.
/// Usable only in translation units compiled by nvcc.
struct cuda {};

} // namespace sphere
