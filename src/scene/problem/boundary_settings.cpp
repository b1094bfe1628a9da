#include "scene/problem/boundary_settings.hpp"

#include <cmath>
#include <utility>

#include "delayspec/errors.hpp"

namespace delayspec::cli {

BoundarySettings read_boundary_settings(Config& config) {
  BoundarySettings s;
  for (const char* key : {"boundary_x", "boundary_y"})
    if (!config.has(key)) throw BadInput(std::string("missing key `") + key + "` (a model parameter, e.g. depth)");
  s.x_key = config.get_string("boundary_x", "");
  s.y_key = config.get_string("boundary_y", "");
  if (s.x_key == s.y_key)
    throw BadInput("`boundary_x = boundary_y = " + s.x_key + "`: two different model keys are needed");
  BoundaryOptions& o = s.options;
  o.x_from = config.require_double("boundary_x_from");
  o.x_to = config.require_double("boundary_x_to");
  o.y_from = config.require_double("boundary_y_from");
  o.y_to = config.require_double("boundary_y_to");
  if (o.x_from == o.x_to) throw BadInput("`boundary_x_from = boundary_x_to = " + format_number(o.x_from) + "`: an empty range");
  if (o.y_from == o.y_to) throw BadInput("`boundary_y_from = boundary_y_to = " + format_number(o.y_from) + "`: an empty range");
  const bool scan = config.get_enum("boundary_starts", false, {{"first", false}, {"scan", true}});
  const int scan_points = static_cast<int>(config.get_int_in_range("boundary_scan_points", 20, 2, 100000));
  if (scan) s.scan_points = scan_points;
  o.step = config.get_double("boundary_step", 0.02);
  o.step_min = config.get_double("boundary_step_min", 1e-6);
  o.step_max = config.get_double("boundary_step_max", 0.1);
  for (const auto& [name, value] : {std::pair{"boundary_step", o.step}, std::pair{"boundary_step_min", o.step_min},
                                    std::pair{"boundary_step_max", o.step_max}})
    if (!(value > 0) || !std::isfinite(value))
      throw BadInput("`" + std::string(name) + " = " + format_number(value) + "`: must be > 0");
  if (o.step_min > o.step_max)
    throw BadInput("`boundary_step_min = " + format_number(o.step_min) + "` exceeds `boundary_step_max = " +
                   format_number(o.step_max) + "`");
  o.max_points = static_cast<int>(config.get_int_in_range("boundary_max_points", 5000, 2, 10'000'000));
  o.chord_error = config.get_double("boundary_chord_error", 1e-4);
  if (!(o.chord_error > 0) || !std::isfinite(o.chord_error))
    throw BadInput("`boundary_chord_error = " + format_number(o.chord_error) + "`: must be > 0");
  o.tolerance = config.get_double("boundary_tolerance", 1e-10);
  if (!(o.tolerance > 0) || !std::isfinite(o.tolerance))
    throw BadInput("`boundary_tolerance = " + format_number(o.tolerance) + "`: must be > 0");
  return s;
}

}  // namespace delayspec::cli
