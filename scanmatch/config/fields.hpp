#pragma once
// The one description of the configuration: every field's JSON key, its command-line flag (if it
// has one) and its help text. config/config_json.hpp reads and writes JSON from it; the CLI adds
// its options from it, and a --config file is overridden by exactly the flags given on the command
// line. A new option is one line in its module's
// description: config/registration_fields.hpp, odometry_fields.hpp, mapping_fields.hpp,
// mapping2d_fields.hpp, and run/run_config_fields.hpp for what a run adds.
//
// A visitor provides
//   template <class T> void operator()(const char* key, T& field, const char* flag,
//                                      const char* help);   // flag nullptr: JSON only
//   template <class S> void nested(const char* key, S& options);  // a nested object
// and describe(options, visitor) calls it for every field. Enumerations are named (enum_name,
// enum_from_name); angles are radians in JSON and Python (the CLI may offer degrees). A bool
// field whose flag starts with "--no-" is switched off by it (`--no-fine`: fine_stage = false);
// any other bool flag switches its field on.

#include <string>

#include "scanmatch/core/error.hpp"
