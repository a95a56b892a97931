#pragma once
/// \file
/// The exception type of the library.
#include <sstream>
#include <stdexcept>
#include <string>

namespace sphere {

/// Every error the library reports: bad input at setup, a particle that leaves the world or
/// becomes non-finite during a run, contact lists beyond 2^32 - 1 entries, a time step
/// above the stable bound. `what()` names the offending value and where it came from.
class error : public std::runtime_error {
public:
    explicit error(const std::string& message) : std::runtime_error("sphere: " + message) {}
};

namespace detail {
/// Streamable parts as one text, numbers with 17 significant digits.
template <class... Parts>
std::string text(const Parts&... parts)
{
    std::ostringstream out;
    out.precision(17);
    (out << ... << parts);
    return out.str();
}

/// Builds a message from streamable parts: `fail("radius ", r, " of particle ", i)`.
template <class... Parts>
[[noreturn]] void fail(const Parts&... parts)
{
    throw error(text(parts...));
}
} // namespace detail
} // namespace sphere
