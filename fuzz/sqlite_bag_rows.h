// The ROS 2 bag that fuzz_rosbag_sqlite reads, written from its input (the harness's header has
// the layout): shared with its regression test (tests/test_rosbag.cpp), which must build the
// very same bag from a reproducer.
#pragma once

#include <sqlite3.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace semsegmap::fuzz {

inline void bindValue(sqlite3_stmt* s, int column, const std::string& v) {
  if (v == "n") {
    sqlite3_bind_null(s, column);
  } else if (v.size() > 1 && v[0] == 'i') {
    sqlite3_bind_int64(s, column, std::strtoll(v.c_str() + 1, nullptr, 10));
  } else if (v.size() > 1 && v[0] == 'f') {
    sqlite3_bind_double(s, column, std::strtod(v.c_str() + 1, nullptr));
  } else if (v.size() > 1 && v[0] == 'x') {
    std::string blob;
    for (size_t i = 1; i + 1 < v.size(); i += 2)
      blob += static_cast<char>(std::strtol(v.substr(i, 2).c_str(), nullptr, 16));
    sqlite3_bind_blob(s, column, blob.data(), static_cast<int>(blob.size()), SQLITE_TRANSIENT);
  } else {
    sqlite3_bind_text(s, column, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  }
}

inline std::vector<std::string> rowFields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, '|')) out.push_back(field);
  return out;
}

// The tables as rosbag2 writes them, without its NOT NULL constraints: a broken writer's rows.
inline void writeBagDatabase(const std::filesystem::path& file, std::string_view rows) {
  std::filesystem::remove(file);
  sqlite3* db = nullptr;
  if (sqlite3_open(file.c_str(), &db) != SQLITE_OK)
    throw std::logic_error(file.string() + ": cannot write the database");
  sqlite3_exec(db,
               "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, "
               "serialization_format TEXT, offered_qos_profiles TEXT);"
               "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp "
               "INTEGER, data BLOB); BEGIN;",
               nullptr, nullptr, nullptr);
  std::stringstream in{std::string(rows)};
  std::string line;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = rowFields(line);
    if (f.size() != 5 || (f[0] != "topics" && f[0] != "messages")) continue;
    const std::string sql = f[0] == "topics" ? "INSERT INTO topics VALUES (?, ?, ?, ?, '')"
                                             : "INSERT INTO messages VALUES (?, ?, ?, ?)";
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr);
    for (int c = 1; c <= 4; ++c) bindValue(s, c, f[c]);
    sqlite3_step(s);  // a row SQLite refuses (a text id) is left out, as a writer could not
    sqlite3_finalize(s);
  }
  sqlite3_exec(db, "COMMIT;", nullptr, nullptr, nullptr);
  sqlite3_close(db);
}

}  // namespace semsegmap::fuzz
