// ROS 2 bags in SQLite storage (io/rosbag_sqlite.cpp): the SQLite file format is SQLite's own
// and fuzzed by its authors, so mutated database bytes would only test that. What the reader
// trusts is the content of the tables a bag writer left: this harness builds a database with
// the bag's tables from the input's rows, of any value type (NULLs, text ids, blobs as names),
// and a metadata.yaml, then reads the bag as the bag reader does.
//
// The input: metadata.yaml's text (empty: none), a line "--8<--", then one row a line,
// "topics|id|name|type|serialization_format" or "messages|id|topic_id|timestamp|data"; a value
// is "i<integer>", "f<real>", "x<hex blob>", "n" (NULL) or text.
#include <sqlite3.h>

#include <algorithm>
#include <sstream>
#include <vector>

#include "fuzz_input.h"
#include "semsegmap/io/rosbag_storage.h"

namespace {

namespace fs = std::filesystem;

void bindValue(sqlite3_stmt* s, int column, const std::string& v) {
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

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, '|')) out.push_back(field);
  return out;
}

// The tables as rosbag2 writes them, without its NOT NULL constraints: a broken writer's rows.
void writeDatabase(const fs::path& file, std::string_view rows) {
  fs::remove(file);
  sqlite3* db = nullptr;
  if (sqlite3_open(file.c_str(), &db) != SQLITE_OK) semsegmap::fuzz::finding("cannot write db");
  sqlite3_exec(db,
               "CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT, type TEXT, "
               "serialization_format TEXT, offered_qos_profiles TEXT);"
               "CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER, timestamp "
               "INTEGER, data BLOB); BEGIN;",
               nullptr, nullptr, nullptr);
  std::stringstream in{std::string(rows)};
  std::string line;
  while (std::getline(in, line)) {
    const std::vector<std::string> f = fields(line);
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

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace semsegmap;
  const auto [metadata, rows] = fuzz::splitAt(fuzz::asText(data, size), "--8<--\n");
  const fs::path bag = fuzz::scratch() / "bag";
  fs::remove_all(bag);
  fs::create_directories(bag);
  writeDatabase(bag / "bag_0.db3", rows);
  if (!metadata.empty()) fuzz::writeInput("bag/metadata.yaml", metadata);
  const fs::path opened = metadata.empty() ? bag / "bag_0.db3" : bag;
  fuzz::expectCleanRefusal(bag.string(), [&] {
    auto storage = rosmsg::openBagStorage(opened);
    for (const rosmsg::BagTopic& topic : storage->topics()) {
      const auto refs = storage->messages(topic.name);
      for (size_t i = 0; i < std::min<size_t>(refs.size(), 4); ++i) {
        (void)storage->read(topic.name, refs[i]);
        (void)storage->readPrefix(topic.name, refs[i], 16);
      }
    }
  });
  return 0;
}
