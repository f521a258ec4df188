#pragma once
// Exit codes of the simsr tool: one per error class, all within 1..125, message on stderr.
#include <simsr/core/error.hpp>

#include <cstdio>
#include <exception>
#include <functional>

namespace simsr::cli {

enum ExitCode : int {
  exit_ok = 0,
  exit_error = 1,        ///< any other simsr::Error or std::exception
  exit_parse = 2,        ///< ParseError: a file is malformed or unreadable
  exit_mesh = 3,         ///< MeshError: invalid mesh element
  exit_shape = 4,        ///< ShapeError: arrays of mismatching shapes
  exit_argument = 5,     ///< ArgumentError: a parameter out of range
  exit_convergence = 6,  ///< ConvergenceError
  exit_numerical = 7,    ///< NumericalError: a non-finite loss, gradient, weight or prediction
  exit_usage = 64,       ///< bad command line (EX_USAGE)
};

/// Runs `body`, mapping exceptions to messages on stderr (prefixed by the program name) and exit codes.
inline int run_guarded(const std::function<int()>& body, const char* program = "simsr") {
  try {
    return body();
  } catch (const ParseError& e) {
    std::fprintf(stderr, "%s: error: %s\n", program, e.what());
    return exit_parse;
  } catch (const MeshError& e) {
    std::fprintf(stderr, "%s: invalid mesh: %s\n", program, e.what());
    return exit_mesh;
  } catch (const ShapeError& e) {
    std::fprintf(stderr, "%s: shape mismatch: %s\n", program, e.what());
    return exit_shape;
  } catch (const ArgumentError& e) {
    std::fprintf(stderr, "%s: invalid argument: %s\n", program, e.what());
    return exit_argument;
  } catch (const ConvergenceError& e) {
    std::fprintf(stderr, "%s: no convergence: %s\n", program, e.what());
    return exit_convergence;
  } catch (const NumericalError& e) {
    std::fprintf(stderr, "%s: numerical failure: %s\n", program, e.what());
    return exit_numerical;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: error: %s\n", program, e.what());
    return exit_error;
  }
}

}  // namespace simsr::cli
