// The extension module delayspec._delayspec: runs a command of the CLI library on a Config built
// exactly as the program builds it (a scene file, or a dict standing for one, then the keyword
// arguments as `--set KEY=VALUE`), and returns the command's JSON result as Python objects. The
// pure-Python front end (delayspec/__init__.py) turns those into results with numpy arrays.
//
// One code path with the CLI: the keys, defaults, validation and messages are the command's own;
// the result is the object `COMMAND --json` prints, read back from that text, as `run` reads its
// analyses (nlohmann::json writes each double in its shortest round-trip form, so the numbers are
// the CLI's to the last bit).
//
// The GIL is released while the command runs. A call from Python's main thread polls Python's
// signal handlers between periods (delayspec/cancellation.hpp): Ctrl-C stops the run with
// KeyboardInterrupt (or whatever the SIGINT handler raises), output files written so far stay
// atomic as in the CLI.
#include <atomic>
#include <chrono>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <streambuf>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include "scene/commands/commands.hpp"
#include "scene/keys/config.hpp"
#include "delayspec/cancellation.hpp"
#include "delayspec/errors.hpp"
#include "delayspec/version.hpp"
#include "scene/commands/key_registry.hpp"

namespace py = pybind11;
using delayspec::BadInput;
using delayspec::NumericalFailure;
using delayspec::cli::Config;

namespace {

// Python runs signal handlers only in its main thread. The call made there polls them (taking the
// GIL at most every poll_interval, so other Python threads keep running); the threads working for
// it (a parallel sweep's workers) see the flag. A call from another thread is not interruptible,
// as Python code in such a thread is not.
class PythonSignals final : public delayspec::CancellationCheck {
 public:
  explicit PythonSignals(bool main_thread) : main_thread_(main_thread), owner_(std::this_thread::get_id()) {}

  bool requested() override {
    if (stop_.load(std::memory_order_relaxed)) return true;
    if (!main_thread_ || std::this_thread::get_id() != owner_) return false;
    const auto now = std::chrono::steady_clock::now();
    if (now < next_poll_) return false;
    next_poll_ = now + poll_interval;
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() == 0) return false;
    raised_.emplace();  // fetches (and clears) what the handler raised, e.g. KeyboardInterrupt
    stop_.store(true, std::memory_order_relaxed);
    return true;
  }

  // Rethrows what the signal handler raised (call with the GIL held).
  [[noreturn]] void rethrow() {
    if (raised_) throw *raised_;
    throw py::error_already_set();  // unreachable: stop_ is set only with raised_
  }

 private:
  static constexpr std::chrono::milliseconds poll_interval{50};
  const bool main_thread_;
  const std::thread::id owner_;
  std::chrono::steady_clock::time_point next_poll_{};
  std::atomic<bool> stop_{false};
  std::optional<py::error_already_set> raised_;
};

bool on_main_thread() {
  static const unsigned long main_ident =
      py::module_::import("threading").attr("main_thread")().attr("ident").cast<unsigned long>();
  return PyThread_get_thread_ident() == main_ident;
}

// A Python str as UTF-8. BadInput naming `what` when it has none: a lone surrogate ("\ud800")
// made pybind11's cast raise a bare RuntimeError (issue 61 item 9).
std::string utf8_text(const std::string& what, py::handle text) {
  Py_ssize_t size = 0;
  const char* data = PyUnicode_AsUTF8AndSize(text.ptr(), &size);
  if (!data) {
    PyErr_Clear();
    throw BadInput(what + ": a string that is not valid Unicode (a lone surrogate such as \\ud800): give text "
                   "that UTF-8 can hold");
  }
  return std::string(data, static_cast<size_t>(size));
}

// bytes and bytearray are sequences of integers to Python: as a key's value they were taken as a
// list of numbers (b"ab" -> "97,98"). Refused, naming the key.
void refuse_bytes(const std::string& key, py::handle value) {
  if (PyBytes_Check(value.ptr()) || PyByteArray_Check(value.ptr()))
    throw BadInput("`" + key + "`: a value of Python type " +
                   py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>() +
                   " (give a str: decode the bytes first)");
}

// A Python value -> the text `--set KEY=VALUE` would carry (and a TOML scene value becomes,
// config.cpp): booleans true/false, integers in decimal, floats in the shortest round-trip form,
// sequences joined by commas (Ns = [100, 200] -> "100,200"); numpy scalars and arrays likewise.
// `nested`: value is an element of a list.
std::string key_text(const std::string& key, py::handle value, bool nested = false) {
  if (py::isinstance<py::bool_>(value)) return value.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::str>(value)) return utf8_text("`" + key + "`", value);
  refuse_bytes(key, value);
  // numpy scalars and arrays as the Python values they hold (an array's __index__ would fail).
  if (py::hasattr(value, "__array__") && py::hasattr(value, "ndim"))
    return key_text(key, value.attr(value.attr("ndim").cast<int>() == 0 ? "item" : "tolist")(), nested);
  PyObject* p = value.ptr();
  if (PyLong_Check(p)) return py::str(value);
  if (PyFloat_Check(p)) return delayspec::format_number(value.cast<double>());
  if (py::isinstance<py::sequence>(value)) {
    // A list key's value is a flat list: joined by commas, [[25], [50]] would read as [25, 50].
    if (nested) throw BadInput("`" + key + "`: a nested list (" + py::repr(value).cast<std::string>() +
                               " inside the list): give a flat list of numbers, strings or booleans");
    std::string text;
    for (py::handle element : value) {
      if (!text.empty()) text += ",";
      text += key_text(key, element, true);
    }
    return text;
  }
  throw BadInput("`" + key + "`: a value of Python type " +
                 py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>() +
                 " (give a number, a string, a boolean or a list of them)");
}

// A Python value of a scene dict -> the TOML node a scene file would hold: booleans, integers,
// floats, strings, sequences as arrays, dicts as tables (numpy scalars and arrays as the Python
// values they hold). Config then reads the table as it reads a file (one rule for both).
template <class X>
void add(toml::table& table, const std::string& key, X&& x) {
  table.insert_or_assign(key, std::forward<X>(x));
}
template <class X>
void add(toml::array& array, const std::string&, X&& x) {
  array.push_back(std::forward<X>(x));
}

// Adds `value` to `into` (a table: under `key`; an array: at its end).
template <class Container>
void add_scene_value(Container& into, const std::string& key, py::handle value) {
  if (py::isinstance<py::dict>(value)) {
    toml::table table;
    for (auto [k, v] : value.cast<py::dict>()) add_scene_value(table, utf8_text("a key of `" + key + "`", py::str(k)), v);
    return add(into, key, std::move(table));
  }
  if (py::isinstance<py::bool_>(value)) return add(into, key, value.cast<bool>());
  if (py::isinstance<py::str>(value)) return add(into, key, utf8_text("`" + key + "`", value));
  refuse_bytes(key, value);
  if (py::hasattr(value, "__array__") && py::hasattr(value, "ndim"))
    return add_scene_value(into, key, value.attr(value.attr("ndim").cast<int>() == 0 ? "item" : "tolist")());
  PyObject* p = value.ptr();
  if (PyLong_Check(p)) {
    const long long v = PyLong_AsLongLong(p);
    if (v == -1 && PyErr_Occurred()) {  // beyond 64 bits: its digits, which the key's reader refuses by name
      PyErr_Clear();
      return add(into, key, std::string(py::str(value)));
    }
    return add(into, key, static_cast<int64_t>(v));
  }
  if (PyFloat_Check(p)) return add(into, key, value.cast<double>());
  if (py::isinstance<py::sequence>(value)) {
    toml::array array;
    for (py::handle element : value) add_scene_value(array, key, element);
    return add(into, key, std::move(array));
  }
  throw BadInput("`" + key + "`: a value of Python type " +
                 py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>() +
                 " (give a number, a string, a boolean or a list of them)");
}

Config make_config(const py::object& scene, const py::dict& keys, std::optional<std::string>& scene_path) {
  Config config;
  if (py::isinstance<py::dict>(scene)) {
    toml::table table;
    for (auto [k, v] : scene.cast<py::dict>()) add_scene_value(table, utf8_text("a key of the scene dict", py::str(k)), v);
    config = Config::from_scene_table(table, "the scene dict");
  } else if (!scene.is_none()) {
    scene_path = py::str(py::module_::import("os").attr("fspath")(scene)).cast<std::string>();
    config = Config::from_scene_file(*scene_path);
  }
  for (auto [k, v] : keys) {
    if (v.is_none()) continue;  // None: the key's default (or the scene's value)
    const std::string key = utf8_text("a keyword's name", py::str(k));
    // the origin messages name: "(= 4, from a Python keyword)", not "from --set" (issue 61 item 9)
    config.set(key, key_text(key, v), "a Python keyword");
  }
  return config;
}

py::object to_python(const nlohmann::json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.get<std::uint64_t>());
    case nlohmann::json::value_t::number_float: return py::float_(j.get<double>());
    case nlohmann::json::value_t::string: return py::str(j.get_ref<const std::string&>());
    case nlohmann::json::value_t::array: {
      py::list list(j.size());
      for (size_t i = 0; i < j.size(); ++i) list[i] = to_python(j[i]);
      return list;
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (const auto& [k, v] : j.items()) dict[py::str(k)] = to_python(v);
      return dict;
    }
    default: throw std::runtime_error("a JSON value of an unexpected type");
  }
}

// The stderr of a call with progress=True: each piece the command flushes (a progress line every
// few seconds, a warning) is written to Python's sys.stderr as it comes, so that it shows where
// the user looks (a terminal, a notebook's cell), and kept for the result. Written from the
// computing threads: a mutex orders the pieces and the GIL is taken for each write.
class LiveStderr : public std::streambuf {
 public:
  std::string text() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return all_;
  }

 protected:
  int_type overflow(int_type c) override {
    if (c != traits_type::eof()) {
      const std::lock_guard<std::mutex> lock(mutex_);
      pending_ += traits_type::to_char_type(c);
    }
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    const std::lock_guard<std::mutex> lock(mutex_);
    pending_.append(s, static_cast<size_t>(n));
    return n;
  }
  int sync() override {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (pending_.empty()) return 0;
    {
      py::gil_scoped_acquire gil;
      try {
        const py::object stderr_ = py::module_::import("sys").attr("stderr");
        stderr_.attr("write")(pending_);
        stderr_.attr("flush")();
      } catch (const py::error_already_set&) {
        // no usable sys.stderr (closed, replaced by None): the text is still in the result
      }
    }
    all_ += pending_;
    pending_.clear();
    return 0;
  }

 private:
  std::mutex mutex_;
  std::string pending_;
  std::string all_;
};

// Runs `command` as `delayspec COMMAND [SCENE] --set KEY=VALUE... --json --quiet [--out OUT]`
// (without --quiet when `progress`: its stderr then goes to sys.stderr as it comes, LiveStderr).
// Returns (the JSON result, the bulk arrays the JSON leaves to --out files, the exit status:
// 0, or 3 for failures recorded in a complete result, what the command wrote to stderr).
py::tuple run(const std::string& command, const py::object& scene, const py::dict& keys,
              const std::optional<std::string>& out, bool resume, bool progress) {
  delayspec::cli::command_spec(command);  // BadInput naming the commands when it is none
  std::optional<std::string> scene_path;
  Config config = make_config(scene, keys, scene_path);
  delayspec::cli::check_output_flags(command, out.has_value(), out.value_or(""), resume);
  PythonSignals signals(on_main_thread());
  std::ostringstream json_text, quiet_err;
  LiveStderr live;
  std::ostream live_err(&live);
  std::ostream& err = progress ? live_err : quiet_err;
  nlohmann::json result, arrays = nlohmann::json::object();
  int status = 0;
  bool cancelled = false;
  {
    py::gil_scoped_release released;
    const delayspec::CancellationScope scope(&signals);
    const delayspec::cli::Invocation inv{.command = command,
                                         .scene = scene_path,
                                         .json = true,
                                         .out_dir = out,
                                         .quiet = !progress,
                                         .resume = resume,
                                         .out = json_text,
                                         .err = err,
                                         .arrays = &arrays};
    try {
      status = delayspec::cli::run_command(config, inv);
      err.flush();
      result = nlohmann::json::parse(json_text.str());
    } catch (const delayspec::Cancelled&) {
      cancelled = true;
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error("delayspec " + command +
                               ": internal error (please report): no single JSON result: " + e.what());
    }
  }
  if (cancelled) signals.rethrow();
  return py::make_tuple(to_python(result), to_python(arrays), status, progress ? live.text() : quiet_err.str());
}

}  // namespace

PYBIND11_MODULE(_delayspec, m) {
  m.doc() = "delayspec's command layer (use the package `delayspec`, not this module)";
  m.attr("__version__") = DELAYSPEC_VERSION;
  py::register_exception<BadInput>(m, "BadInput", PyExc_ValueError);
  py::register_exception<NumericalFailure>(m, "NumericalFailure", PyExc_RuntimeError);
  m.def("run", &run, py::arg("command"), py::arg("scene"), py::arg("keys"), py::arg("out"), py::arg("resume"),
        py::arg("progress") = false,
        "Runs a command as `delayspec COMMAND --json`: (result, arrays, status, stderr text). With progress, its "
        "stderr (progress lines, warnings) is written to sys.stderr as it comes.");
  m.def(
      "commands",
      [] {
        py::list rows;
        for (const auto& spec : delayspec::cli::command_table()) {
          py::dict row;
          row["name"] = spec.name;
          row["summary"] = spec.summary;
          row["writes_out"] = spec.out == delayspec::cli::OutDirUse::written;
          row["resume"] = spec.resume;
          rows.append(row);
        }
        return rows;
      },
      "The command table: name, summary (the first line of `delayspec COMMAND --help`), whether the command "
      "writes files into out= and resumes with resume=True.");
  m.def(
      "keys_help", [](const std::string& command) { return delayspec::cli::command_keys_help(command); },
      py::arg("command"), "The keys COMMAND reads, with their defaults (the tail of `delayspec COMMAND --help`).");
}
