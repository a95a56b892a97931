#pragma once
/// \file
/// Execution policies: tag types that select where kernels run.

namespace sphere {

/// Kernels run on CPU threads through OpenMP (sorts and scans on the calling thread). Every
/// test runs on this backend; the CUDA test binary runs some of the same sources on `cuda`.
struct host {};

/// Kernels run on an NVIDIA GPU; sorts, scans and reductions through CUB (and Thrust).
/// Usable only in translation units compiled by nvcc.
struct cuda {};

/// Whether a policy runs kernels on a few CPU threads, each taking a large block of indices
/// (the host), rather than one GPU thread per index. Schedules that hand a thread a block of
/// work (the slab schedule of the pair sums, several grid cells per kernel index) ask this;
/// nothing outside exec/ asks which policy it is.
template <class Policy>
inline constexpr bool runs_in_blocks = false;
template <>
inline constexpr bool runs_in_blocks<host> = true;

} // namespace sphere
