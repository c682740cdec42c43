#include "scanmatch/odometry/config_io.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <type_traits>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"

namespace scanmatch {
namespace {

using Json = nlohmann::ordered_json;

const char* kernel_name(KernelType type) {
  switch (type) {
    case KernelType::kNone:
      return "none";
    case KernelType::kHuber:
      return "huber";
    case KernelType::kCauchy:
      return "cauchy";
    case KernelType::kTukey:
      return "tukey";
    case KernelType::kGemanMcClure:
      return "geman-mcclure";
  }
  return "none";
}

// One table of fields drives both directions, so writing and reading cannot drift apart.
template <typename Visitor>
void visit(OdometryConfig& c, Visitor&& v) {
  v("method", c.method);
  v("voxel_size", c.voxel_size);
  v("min_range", c.min_range);
  v("max_range", c.max_range);
  v("ndt_resolution", c.ndt_resolution);
  v("ndt_neighbours", c.ndt_neighbours);
  v("coarse_voxel_size", c.coarse_voxel_size);
  v("coarse_max_iterations", c.coarse_max_iterations);
  v("map_voxel_size", c.map_voxel_size);
  v("merge_threshold", c.merge_threshold);
  v("map_radius", c.map_radius);
  v("map_voxel_min_points", c.map_voxel_min_points);
  v("map_voxel_max_points", c.map_voxel_max_points);
  v("fine_max_iterations", c.fine_max_iterations);
  v("fine_tolerance", c.fine_tolerance);
  v("fine_max_flatness", c.fine_max_flatness);
  v("fine_kernel_distance", c.fine_kernel_distance);
  v("degeneracy_ratio", c.degeneracy_ratio);
  v("fine_stage", c.fine_stage);
  v("map_update", c.map_update);
  v("constant_velocity", c.constant_velocity);
  v("deskew", c.deskew);
  v("deskew_min_translation", c.deskew_min_translation);
  v("deskew_min_rotation", c.deskew_min_rotation);
  v("max_jump", c.max_jump);
  v("max_jump_angle", c.max_jump_angle);
  v("threads", c.threads);
}

template <typename Visitor>
void visit(RegistrationOptions& r, Visitor&& v) {
  v("max_correspondence_distance", r.max_correspondence_distance);
  v("normal_neighbours", r.normal_neighbours);
  v("covariance_neighbours", r.covariance_neighbours);
  v("gicp_epsilon", r.gicp_epsilon);
  v("voxel_resolution", r.voxel_resolution);
  v("voxel_neighbours", r.voxel_neighbours);
  v("ndt_outlier_ratio", r.ndt_outlier_ratio);
  v("ctf_epsilon", r.ctf_epsilon);
}

template <typename Visitor>
void visit(SolverOptions& s, Visitor&& v) {
  v("max_iterations", s.max_iterations);
  v("rotation_tolerance", s.rotation_tolerance);
  v("translation_tolerance", s.translation_tolerance);
  v("relative_cost_tolerance", s.relative_cost_tolerance);
  v("levenberg_marquardt", s.levenberg_marquardt);
  v("initial_lambda", s.initial_lambda);
  v("kernel_scale", s.kernel.scale);
}

template <typename Visitor>
void visit(LoamFeatureOptions& l, Visitor&& v) {
  v("neighbours", l.neighbours);
  v("segments", l.segments);
  v("edges_per_segment", l.edges_per_segment);
  v("planes_per_segment", l.planes_per_segment);
  v("edge_threshold", l.edge_threshold);
  v("plane_threshold", l.plane_threshold);
  v("occlusion_ratio", l.occlusion_ratio);
  v("rings", l.rings);
}

template <typename T>
Json to_object(T& options) {
  Json j = Json::object();
  visit(options, [&](const char* key, auto& field) { j[key] = field; });
  return j;
}

template <typename T>
void from_object(const Json& j, T& options, const std::string& source, const std::string& path,
                 const std::vector<std::string>& nested) {
  if (!j.is_object())
    fail(source, path.empty() ? "expected a JSON object" : path + ": expected an object");
  for (const auto& [key, value] : j.items()) {
    bool known = std::find(nested.begin(), nested.end(), key) != nested.end();
    visit(options, [&](const char* name, auto& field) {
      if (key != name) return;
      known = true;
      using Field = std::decay_t<decltype(field)>;
      try {
        if constexpr (std::is_same_v<Field, bool>) {
          if (!value.is_boolean()) throw std::invalid_argument("");
        } else if constexpr (std::is_same_v<Field, std::string>) {
          if (!value.is_string()) throw std::invalid_argument("");
        } else {
          if (!value.is_number()) throw std::invalid_argument("");
          if constexpr (std::is_unsigned_v<Field>)
            if (value.template get<double>() < 0) throw std::invalid_argument("");
        }
        field = value.template get<Field>();
      } catch (const std::exception&) {
        fail(source, "key '" + path + key + "' has the wrong type or value (" + value.dump() + ")");
      }
    });
    if (!known) fail(source, "unknown key '" + path + key + "'");
  }
}

}  // namespace

std::string odometry_config_to_json(const OdometryConfig& config) {
  OdometryConfig c = config;
  Json j = to_object(c);
  Json registration = to_object(c.registration);
  Json solver = to_object(c.registration.solver);
  solver["kernel"] = kernel_name(c.registration.solver.kernel.type);
  registration["solver"] = solver;
  registration["loam"] = to_object(c.registration.loam);
  j["registration"] = registration;
  return j.dump(2) + "\n";
}

OdometryConfig odometry_config_from_json(const std::string& text, const std::string& source,
                                         const OdometryConfig& base) {
  Json j;
  try {
    j = Json::parse(text);
  } catch (const Json::parse_error& e) {
    fail(source, std::string("not valid JSON: ") + e.what());
  }
  OdometryConfig c = base;
  from_object(j, c, source, "", {"registration"});
  if (j.contains("registration")) {
    const Json& r = j["registration"];
    from_object(r, c.registration, source, "registration.", {"solver", "loam"});
    if (r.contains("solver")) {
      Json solver = r["solver"];
      if (solver.is_object() && solver.contains("kernel")) {
        if (!solver["kernel"].is_string())
          fail(source, "key 'registration.solver.kernel' must be a string");
        try {
          c.registration.solver.kernel.type = parse_kernel(solver["kernel"].get<std::string>());
        } catch (const Error& e) {
          fail(source, e.what());
        }
        solver.erase("kernel");
      }
      from_object(solver, c.registration.solver, source, "registration.solver.", {});
    }
    if (r.contains("loam"))
      from_object(r["loam"], c.registration.loam, source, "registration.loam.", {});
  }
  return c;
}

OdometryConfig read_odometry_config(const std::string& path, const OdometryConfig& base) {
  return odometry_config_from_json(read_file_bytes(path), path, base);
}

}  // namespace scanmatch
