// The thread governor (exec/thread_governor.cuh): its decision between all threads and one,
// fed with synthetic step times, and the limit it sets on the host loops' teams. That the
// physics does not depend on the team is tested in test_determinism.cpp.
#include <catch2/catch.hpp>

#include <sphere/exec/algorithms.cuh>
#include <sphere/exec/for_each.cuh>
#include <sphere/exec/thread_governor.cuh>

#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <vector>

// This file's tests and helpers in a namespace of their own: the test sources are compiled
// several to a translation unit (tests/CMakeLists.txt).
namespace test_threads {

namespace {

using sphere::team_choice;

/// Feeds `steps` steps to `c`, each lasting seconds_on(team) for the team it runs on, and
/// returns the teams used, step by step.
template <class Time>
std::vector<int> drive(team_choice& c, int steps, Time seconds_on)
{
    std::vector<int> teams;
    int team = c.team();
    for (int k = 0; k < steps; ++k) {
        teams.push_back(team);
        team = c.next(seconds_on(team, k));
    }
    return teams;
}

/// How many maximal runs of consecutive steps on `team` `teams` holds.
int runs(const std::vector<int>& teams, int team)
{
    int n = 0;
    for (std::size_t k = 0; k < teams.size(); ++k) n += teams[k] == team && (k == 0 || teams[k - 1] != team);
    return n;
}

int count(const std::vector<int>& teams, int team, std::size_t from = 0)
{
    int n = 0;
    for (std::size_t k = from; k < teams.size(); ++k) n += teams[k] == team;
    return n;
}

/// Restores the OpenMP thread count and lifts the team limit when a test leaves.
struct thread_state_guard {
    int saved = omp_get_max_threads();
    ~thread_state_guard()
    {
        omp_set_num_threads(saved);
        sphere::host_team_limit() = 0;
    }
};

} // namespace

TEST_CASE("team_choice keeps all threads where they are faster, probing one thread ever more rarely", "[threads]")
{
    team_choice c(2);
    REQUIRE(c.team() == 2);
    // An idle machine: 2 threads take 1 ms per step, 1 thread 1.9 ms.
    const std::vector<int> teams = drive(c, 20000, [](int team, int) { return team == 2 ? 1e-3 : 1.9e-3; });
    // Each comparison probes one thread for at most a window; the first is at the start, then
    // the pauses double from 32 to 4096 steps: 20000 steps hold 11 comparisons (after pauses
    // 32, 64, ..., 4096, then 4096 and 4096). A probe ends once it has lost: after its first
    // (uncounted) step and 8 steps of 1.9 ms, more than 0.85 x 16 x 1 ms.
    CHECK(runs(teams, 1) == 11);
    CHECK(count(teams, 1) == 11 * 9);
    CHECK(count(teams, 1, 10000) <= 2 * team_choice::window); // under 0.2% of a long run
    CHECK(teams.back() == 2);
}

TEST_CASE("team_choice moves to one thread when one is faster, and back when the load goes", "[threads]")
{
    team_choice c(2);
    // A busy machine for the first 10000 steps (2 threads 3 ms, 1 thread 1 ms), idle after.
    const auto busy_then_idle = [](int team, int k) {
        if (k < 10000) return team == 2 ? 3e-3 : 1e-3;
        return team == 2 ? 1e-3 : 1.9e-3;
    };
    const std::vector<int> teams = drive(c, 20000, busy_then_idle);
    // The first comparison ends after two windows and switches; from then on only the probes
    // of 2 threads run on 2 threads, after pauses of 32, 64, ..., 4096 steps: 8 comparisons
    // before step 10000, each ending after its first step and 5 of 3 ms (> 0.85 x 16 x 1 ms).
    CHECK(teams[2 * team_choice::window] == 1);
    const std::vector<int> busy(teams.begin() + 2 * team_choice::window, teams.begin() + 10000);
    CHECK(runs(busy, 2) == 8);
    CHECK(count(busy, 2) == 8 * 6);
    // Back to 2 threads within one pause (4096 steps by then) and a comparison.
    const int back_by = 10000 + int(team_choice::longest_pause) + 2 * team_choice::window;
    CHECK(teams[back_by] == 2);
    CHECK(teams.back() == 2);
}

TEST_CASE("team_choice keeps the current team when the other is not clearly faster", "[threads]")
{
    team_choice c(2);
    // One thread only 5% faster: within the margin, so no switch, whatever the noise pattern.
    const std::vector<int> teams =
        drive(c, 5000, [](int team, int k) { return (team == 2 ? 1e-3 : 0.95e-3) * (1 + 0.01 * (k % 3)); });
    CHECK(teams.back() == 2);
    CHECK(count(teams, 2) > 4500);
    // One thread available: nothing to choose.
    team_choice single(1);
    CHECK(drive(single, 500, [](int, int) { return 1e-3; }) == std::vector<int>(500, 1));
}

TEST_CASE("host_team_limit caps the threads of the host loops", "[threads]")
{
    thread_state_guard guard;
    omp_set_num_threads(2);
    constexpr std::size_t n = 64 * sphere::host_chunk;
    auto most_seen = [] {
        std::vector<int> seen(n);
        int* out = seen.data();
        sphere::for_each_index(sphere::host{}, n, [out](std::size_t i) { out[i] = omp_get_num_threads(); });
        int most = 0;
        for (int t : seen) most = t > most ? t : most;
        return most;
    };
    sphere::host_team_limit() = 1;
    CHECK(sphere::host_team() == 1);
    CHECK(most_seen() == 1);
    sphere::host_team_limit() = 0;
    CHECK(sphere::host_team() == 2);
    CHECK(most_seen() == 2);
}

TEST_CASE("the largest and the smallest of a host reduction, in lanes, on any team", "[threads]")
{
    // max_op and min_op combine a chunk's values in eight lanes (sphere::order_free): every
    // length around the lanes and the chunks, with the extreme in the first lane, in the
    // remainder after the last full group of eight, in the last chunk and repeated.
    thread_state_guard guard;
    omp_set_num_threads(2);
    const std::size_t chunk = sphere::host_chunk;
    for (std::size_t n : {std::size_t(1), std::size_t(2), std::size_t(8), std::size_t(9), std::size_t(17), chunk - 1,
                          chunk, chunk + 1, 3 * chunk + 5, 20 * chunk - 3}) {
        std::vector<double> values(n);
        std::uint32_t state = 12345;
        for (double& v : values) {
            state = state * 1664525u + 1013904223u;
            v = double(state % 1000) - 500; // in [-500, 500)
        }
        for (std::size_t at : {std::size_t(0), n - 1, n / 2, (n - 1) / 8 * 8, n > 3 ? n - 3 : std::size_t(0)}) {
            std::vector<double> v = values;
            v[at] = 1e9;
            v[n - 1 - at] = -1e9;
            const double* data = v.data();
            const auto value = [data](std::size_t i) { return data[i]; };
            for (int team : {1, 2}) {
                sphere::host_team_limit() = team;
                INFO("n = " << n << ", extremes at " << at << " and " << n - 1 - at << ", team of " << team);
                CHECK(sphere::transform_reduce(sphere::host{}, n, value, -1e300, sphere::max_op{}) ==
                      *std::max_element(v.begin(), v.end()));
                CHECK(sphere::transform_reduce(sphere::host{}, n, value, 1e300, sphere::min_op{}) ==
                      *std::min_element(v.begin(), v.end()));
                CHECK(sphere::transform_reduce(sphere::host{}, n, value, 2e9, sphere::max_op{}) == 2e9); // init counts
            }
            sphere::host_team_limit() = 0;
        }
    }
}

TEST_CASE("thread_governor obeys OMP_NUM_THREADS and SPHERE_ADAPT_THREADS=0", "[threads]")
{
    thread_state_guard guard;
    omp_set_num_threads(2);
    const char* omp = std::getenv("OMP_NUM_THREADS");
    const std::string saved = omp ? omp : "";
    {
        setenv("OMP_NUM_THREADS", "2", 1); // an explicit count: the governor stays off
        sphere::thread_governor g;
        for (int k = 0; k < 100; ++k) g.step();
        CHECK(sphere::host_team_limit() == 0);
    }
    unsetenv("OMP_NUM_THREADS");
    {
        setenv("SPHERE_ADAPT_THREADS", "0", 1);
        sphere::thread_governor g;
        g.step();
        CHECK(sphere::host_team_limit() == 0);
        unsetenv("SPHERE_ADAPT_THREADS");
    }
    {
        sphere::thread_governor g; // adapting: the first step runs on all threads
        g.step();
        CHECK(sphere::host_team_limit() == 2);
    }
    {
        // Another simulation's governor has limited the thread to one: this one still adapts.
        sphere::host_team_limit() = 1;
        sphere::thread_governor g;
        g.step();
        CHECK(sphere::host_team_limit() == 2);
    }
    CHECK(sphere::host_team_limit() == 0); // lifted when the governor goes
    if (omp) setenv("OMP_NUM_THREADS", saved.c_str(), 1);
}

} // namespace test_threads
