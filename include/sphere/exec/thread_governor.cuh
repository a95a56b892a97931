#pragma once
/// \file
/// `thread_governor`: picks, step by step, whether a simulation's host loops run on all of
/// OpenMP's threads or on one, by timing both. On a machine where another job holds a core,
/// a team of threads that synchronises several times per step waits for the thread that
/// shares its core, and libgomp's spinning idle threads take time from the one with work:
/// a small run can take several times longer on two threads than on one
/// (docs/performance.md, *OpenMP on a shared machine*). Results do not depend on the
/// choice: every host loop gives the same bits on any number of threads.
#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <string_view>

#include "host_team.cuh"

namespace sphere {

/// The decision of thread_governor, apart from clocks: fed the wall time of every step, it
/// answers the number of threads for the next one. It runs `window` steps on the current
/// team, then up to `window` on the other (1 against all `most` threads), and switches when
/// the other took less time by `margin`. The first step of each window is not counted (it
/// pays for waking the threads), and a probe of the other team ends as soon as it has lost.
/// Totals, not medians: on a busy machine most steps of a team are as fast as one thread's,
/// and every few steps one waits milliseconds for a thread that shares its core; those waits
/// are the cost. After a comparison it runs `pause` steps before the next; the pause doubles
/// while the choice holds (up to `longest_pause`) and restarts at `first_pause` after a switch,
/// so a long run re-checks rarely and a change of load is followed within a few thousand steps.
class team_choice {
public:
    static constexpr int window = 17;
    static constexpr long first_pause = 32, longest_pause = 4096;
    static constexpr double margin = 0.85;

    explicit team_choice(int most) : most_(most < 1 ? 1 : most), team_(most_) {}

    int team() const { return team_; }

    /// Books the duration of the step just run (s) and returns the team for the next step.
    int next(double seconds)
    {
        if (most_ == 1) return team_;
        switch (stage_) {
        case stage::pause:
            if (--left_ <= 0) start(stage::current);
            break;
        case stage::current:
            if (book(seconds, current_)) {
                start(stage::other);
                team_ = other();
            }
            break;
        case stage::other:
            // A probe ends as soon as it has lost: on a crowded machine a step on the other
            // team can take 100 times as long as on the current one.
            if (book(seconds, other_) || other_ >= margin * current_) {
                const bool switch_team = count_ == window && other_ < margin * current_;
                if (!switch_team) team_ = other(); // back to the current team
                pause_ = switch_team ? first_pause : std::min(2 * pause_, longest_pause);
                left_ = pause_;
                stage_ = stage::pause;
            }
            break;
        }
        return team_;
    }

private:
    enum class stage { pause, current, other };

    int other() const { return team_ == most_ ? 1 : most_; }

    void start(stage s)
    {
        stage_ = s;
        count_ = 0;
    }

    /// Books a step of the window being measured into its total; true when the window is full.
    bool book(double seconds, double& total)
    {
        if (count_ == 0) total = 0; // the first step of a window is not counted
        else total += seconds;
        return ++count_ == window;
    }

    int most_, team_;
    stage stage_ = stage::current;
    int count_ = 0;
    long pause_ = first_pause / 2, left_ = 0;
    double current_ = 0, other_ = 0; ///< the windows' total times (s)
};

/// Times the steps of one simulation and sets host_team_limit() for the next one
/// (team_choice). Off when OMP_NUM_THREADS is set (the user chose a count: it is obeyed) or
/// OpenMP has one thread; `SPHERE_ADAPT_THREADS=0` turns it off too.
class thread_governor {
public:
    thread_governor() : choice_(host_threads()), on_(enabled()) {}
    thread_governor(const thread_governor&) = default;
    thread_governor(thread_governor&&) = default;
    thread_governor& operator=(const thread_governor&) = default;
    thread_governor& operator=(thread_governor&&) = default;
    /// Lifts the limit, so that later host loops of the thread (another solver) use all threads.
    ~thread_governor()
    {
        if (on_) host_team_limit() = 0;
    }

    /// At the start of every step.
    void step()
    {
        if (!on_) return;
        const clock::time_point now = clock::now();
        if (started_) host_team_limit() = choice_.next(std::chrono::duration<double>(now - last_).count());
        else host_team_limit() = choice_.team();
        started_ = true;
        last_ = now;
    }

private:
    using clock = std::chrono::steady_clock;

    static bool enabled()
    {
        if (host_threads() == 1 || std::getenv("OMP_NUM_THREADS") != nullptr) return false;
        const char* adapt = std::getenv("SPHERE_ADAPT_THREADS");
        return adapt == nullptr || std::string_view(adapt) != "0";
    }

    team_choice choice_;
    bool on_, started_ = false;
    clock::time_point last_;
};

} // namespace sphere
