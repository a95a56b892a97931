#pragma once
/// \file
/// How many OpenMP threads the host loops of the calling thread use: OpenMP's count
/// (`OMP_NUM_THREADS`, `omp_set_num_threads`), or fewer while a simulation's thread governor
/// (exec/thread_governor.cuh) has measured that fewer are faster. Results do not depend on
/// it: every host loop and reduction gives the same bits on any number of threads.
#ifdef _OPENMP
#include <omp.h>
#endif

namespace sphere {

/// The calling thread's limit on the host loops' threads (0: none). Set by thread_governor.
inline int& host_team_limit()
{
    static thread_local int limit = 0;
    return limit;
}

/// OpenMP's thread count for the calling thread (1 without OpenMP).
inline int host_threads()
{
#ifdef _OPENMP
    return omp_get_max_threads();
#else
    return 1;
#endif
}

/// The number of threads a host loop starts: host_threads(), capped by host_team_limit().
inline int host_team()
{
    const int most = host_threads(), limit = host_team_limit();
    return limit > 0 && limit < most ? limit : most;
}

} // namespace sphere
