#pragma once
// `sphere --film` (docs/program.md, *Pictures*): the run's pictures joined into a video by
// ffmpeg, when it is installed. ffmpeg is started directly (fork and exec, no shell), so that
// folder names need no quoting.
#include <sphere/core/error.cuh>

#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <string>
#include <vector>

namespace program {

/// Runs ffmpeg on the pictures `<folder>/<name>.output%05d.png` at `fps` frames per second,
/// writing `<folder>/<name>.mp4`; returns false, with a note on stderr, when no ffmpeg is on
/// the PATH. Throws sphere::error when ffmpeg fails.
inline bool write_film(const std::string& folder, const std::string& name, double fps)
{
    const std::string frames = folder + "/" + name + ".output%05d.png", film = folder + "/" + name + ".mp4";
    const std::string rate = std::to_string(fps);
    std::vector<std::string> args{"ffmpeg", "-y", "-loglevel", "error", "-framerate", rate, "-i", frames,
                                  "-pix_fmt", "yuv420p", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", film};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::fflush(nullptr);
    const pid_t child = fork();
    if (child < 0) sphere::detail::fail("--film: cannot start ffmpeg (fork failed)");
    if (child == 0) {
        execvp("ffmpeg", argv.data());
        _exit(127); // not found
    }
    int status = 0;
    if (waitpid(child, &status, 0) < 0) sphere::detail::fail("--film: lost track of ffmpeg");
    if (WIFEXITED(status) && WEXITSTATUS(status) == 127) {
        std::fprintf(stderr, "sphere: --film: no ffmpeg on the PATH (Debian: ffmpeg); the pictures are in %s/\n",
                     folder.c_str());
        return false;
    }
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
        sphere::detail::fail("--film: ffmpeg failed (exit status ", WIFEXITED(status) ? WEXITSTATUS(status) : -1,
                             ") joining ", frames, " into ", film);
    return true;
}

} // namespace program
