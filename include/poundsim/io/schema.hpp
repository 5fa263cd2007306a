#pragma once
/// @file
/// The JSON Schema of a model file, generated from the declared fields (fields.hpp) of its
/// tables, from keys::File down: every key with its type, range or admitted names, default, unit
/// and meaning; sub-tables and arrays of tables; a law's tag choosing which parameters its table
/// holds. Editors complete and check model files with it (docs/input.md#editor-completion).
///
/// The schema says what a key may hold; the reader's rules between keys (either–or keys, a
/// joint width against a stroke, keys only for some analyses) stay the reader's. A file the
/// reader accepts is valid against the schema; a misspelt key or a value of the wrong type is
/// not (python/tests/test_schema.py checks both on every example and every malformed case).

#include <string>

namespace poundsim::io {

/// The schema (JSON Schema draft 7) as indented JSON text.
[[nodiscard]] std::string input_schema();

}  // namespace poundsim::io
