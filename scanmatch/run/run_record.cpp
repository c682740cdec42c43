#include "scanmatch/run/run_record.hpp"

#include <filesystem>
#include <system_error>

#include "scanmatch/core/error.hpp"
#include "scanmatch/io/file_util.hpp"

namespace scanmatch {

void create_run_folder(const std::string& path) {
  std::error_code ec;
  std::filesystem::create_directories(path, ec);
  if (ec) fail(path, "cannot create the run folder: " + ec.message());
}

void write_json_atomic(const std::string& path, const nlohmann::ordered_json& j) {
  write_file_atomic(path, j.dump(2) + "\n");
}

}  // namespace scanmatch
