#pragma once
/// \file
/// The one exception hierarchy of simsr. Every message says what went wrong and where, so a user
/// can find the offending file line, mesh element or array without a debugger.

#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace simsr {

/// Base of every simsr exception.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
};

/// A file could not be read or written (missing, unreadable, or not in the expected format).
/// `line` is 1-based for text formats; binary formats report 0 and put the byte offset in the text.
class ParseError : public Error {
 public:
  ParseError(std::string file, std::int64_t line, const std::string& message)
      : Error(format(file, line, message)), file_(std::move(file)), line_(line), message_(message) {}
  const std::string& file() const noexcept { return file_; }
  std::int64_t line() const noexcept { return line_; }
  const std::string& message() const noexcept { return message_; }

 private:
  static std::string format(const std::string& file, std::int64_t line, const std::string& message) {
    std::ostringstream s;
    s << file;
    if (line > 0) s << ':' << line;
    s << ": " << message;
    return s.str();
  }
  std::string file_;
  std::int64_t line_;
  std::string message_;
};

/// An output file could not be written (its folder is missing or not writable, the disk is full,
/// the close or the rename failed): `file()` is the target as given, `message()` says what failed
/// in the operating system's words, `error_code()` is the errno (0 when none applies). A ParseError
/// with line 0, so every handler of file errors (the tool's exit code 2 among them) catches it; the
/// previous file at `file()`, if any, is left as it was (io/atomic_file.hpp).
class WriteError : public ParseError {
 public:
  WriteError(std::string file, const std::string& message, int error_code = 0)
      : ParseError(std::move(file), 0, message), error_code_(error_code) {}
  int error_code() const noexcept { return error_code_; }

 private:
  int error_code_;
};

/// A mesh is invalid: `element` is the offending element (tet, triangle or vertex, as `kind` says),
/// -1 when the problem concerns the mesh as a whole.
class MeshError : public Error {
 public:
  MeshError(std::string kind, std::int64_t element, const std::string& message)
      : Error(format(kind, element, message)), kind_(std::move(kind)), element_(element) {}
  const std::string& kind() const noexcept { return kind_; }
  std::int64_t element() const noexcept { return element_; }

 private:
  static std::string format(const std::string& kind, std::int64_t element, const std::string& message) {
    std::ostringstream s;
    if (element >= 0)
      s << kind << ' ' << element << ": " << message;
    else
      s << kind << ": " << message;
    return s.str();
  }
  std::string kind_;
  std::int64_t element_;
};

/// Array shapes disagree: `what` names the array, `expected`/`got` its shapes (-1 = any size).
class ShapeError : public Error {
 public:
  ShapeError(const std::string& what, std::vector<std::int64_t> expected, std::vector<std::int64_t> got)
      : Error(format(what, expected, got)), expected_(std::move(expected)), got_(std::move(got)) {}
  const std::vector<std::int64_t>& expected() const noexcept { return expected_; }
  const std::vector<std::int64_t>& got() const noexcept { return got_; }

  static std::string shape_string(const std::vector<std::int64_t>& s) {
    std::ostringstream o;
    o << '(';
    for (std::size_t i = 0; i < s.size(); ++i) {
      if (i) o << ", ";
      if (s[i] < 0)
        o << '*';
      else
        o << s[i];
    }
    o << ')';
    return o.str();
  }

 private:
  static std::string format(const std::string& what, const std::vector<std::int64_t>& e,
                            const std::vector<std::int64_t>& g) {
    return what + ": expected shape " + shape_string(e) + ", got " + shape_string(g);
  }
  std::vector<std::int64_t> expected_;
  std::vector<std::int64_t> got_;
};

/// An iterative solver stopped without meeting its tolerance.
class ConvergenceError : public Error {
 public:
  ConvergenceError(const std::string& solver, std::int64_t iterations, double residual)
      : Error(format(solver, iterations, residual)), iterations_(iterations), residual_(residual) {}
  std::int64_t iterations() const noexcept { return iterations_; }
  double residual() const noexcept { return residual_; }

 private:
  static std::string format(const std::string& solver, std::int64_t it, double r) {
    std::ostringstream s;
    s << solver << ": no convergence after " << it << " iterations (residual " << r << ')';
    return s.str();
  }
  std::int64_t iterations_;
  double residual_;
};

/// A computation produced a non-finite value where none may appear (a training loss, a gradient,
/// a weight, a prediction): names what (`tensor`) and when (`step`, −1 when not in a loop).
class NumericalError : public Error {
 public:
  NumericalError(const std::string& where, const std::string& tensor, std::int64_t step, double value)
      : Error(format(where, tensor, step, value)), tensor_(tensor), step_(step) {}
  const std::string& tensor() const noexcept { return tensor_; }
  std::int64_t step() const noexcept { return step_; }

 private:
  static std::string format(const std::string& where, const std::string& tensor, std::int64_t step, double value) {
    std::ostringstream s;
    s << where << ": " << tensor << " is not finite (" << value << ')';
    if (step >= 0) s << " at step " << step;
    return s.str();
  }
  std::string tensor_;
  std::int64_t step_;
};

/// A parameter is outside its valid range (negative k, activation outside [0,1], ...).
class ArgumentError : public Error {
 public:
  explicit ArgumentError(const std::string& what) : Error(what) {}
};

}  // namespace simsr
