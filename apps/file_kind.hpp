#pragma once
// What kind of input a path is, for commands that accept several (info, convert).

#include <string>

namespace scanmatch::cli {

enum class FileKind { kCloud, kTrajectory, kCarmen, kSequence };

/// Folders are sequences; .log is CARMEN; .pcd .ply .bin .xyz .csv are clouds; a .txt is a
/// trajectory when its first data line has 12 or 8 numbers and a cloud otherwise. A path that
/// does not exist is judged by its extension alone (outputs). ".gz" is ignored.
FileKind detect_file_kind(const std::string& path);

}  // namespace scanmatch::cli
