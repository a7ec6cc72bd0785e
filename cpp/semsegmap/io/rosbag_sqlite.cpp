// ROS 2 bags in sqlite3 storage: each .db3 has a `topics` table (id, name, type,
// serialization_format, ...) and a `messages` table (id, topic_id, timestamp in ns, data). A bag
// folder's metadata.yaml lists the files of a split bag and says the storage and compression.
#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <map>
#include <stdexcept>

#include "semsegmap/core/shown_text.h"
#include "semsegmap/io/rosbag_storage.h"

namespace semsegmap::rosmsg {
namespace {

namespace fs = std::filesystem;

// The file's name as read (from metadata.yaml, it may hold any byte) on one line.
[[noreturn]] void fail(const fs::path& file, const std::string& what) {
  throw std::runtime_error(shownText(file.string(), 4096) + ": " + what);
}

struct DbCloser {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct StmtFinalizer {
  void operator()(sqlite3_stmt* s) const { sqlite3_finalize(s); }
};
using Db = std::unique_ptr<sqlite3, DbCloser>;
using Stmt = std::unique_ptr<sqlite3_stmt, StmtFinalizer>;

// One .db3 file, read-only; every sqlite error becomes one line naming the file.
class Database {
 public:
  explicit Database(fs::path file) : file_(std::move(file)) {
    sqlite3* db = nullptr;
    const int rc = sqlite3_open_v2(file_.c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
    db_.reset(db);
    if (rc != SQLITE_OK) fail(file_, std::string("cannot open (") + sqlite3_errstr(rc) + ")");
  }
  Stmt prepare(const char* sql) const {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db_.get(), sql, -1, &s, nullptr) != SQLITE_OK)
      fail(file_, std::string("not a readable ROS 2 bag database (sqlite: ") +
                      sqlite3_errmsg(db_.get()) + ")");
    return Stmt(s);
  }
  // Steps a statement: true with a row, false at the end.
  bool step(sqlite3_stmt* s) const {
    const int rc = sqlite3_step(s);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    fail(file_,
         std::string("corrupt ROS 2 bag database (sqlite: ") + sqlite3_errmsg(db_.get()) + ")");
  }
  const fs::path& file() const { return file_; }

 private:
  fs::path file_;
  Db db_;
};

struct TopicInFile {
  int64_t id = 0;
  std::string serialization;
};

// The files of a bag folder and their storage: metadata.yaml's list when there is one, else every
// .db3 (or else every .mcap) file.
struct BagFiles {
  std::string storage = "sqlite3";
  std::vector<fs::path> files;
};

BagFiles filesWithoutMetadata(const fs::path& folder) {
  BagFiles out;
  for (const char* ext : {".db3", ".mcap"}) {
    for (const auto& entry : fs::directory_iterator(folder))
      if (entry.path().extension() == ext) out.files.push_back(entry.path());
    if (!out.files.empty()) {
      out.storage = ext == std::string(".db3") ? "sqlite3" : "mcap";
      std::sort(out.files.begin(), out.files.end());
      return out;
    }
  }
  fail(folder, "no metadata.yaml and no .db3 or .mcap file: not a ROS 2 bag folder");
}

BagFiles bagFiles(const fs::path& folder) {
  const fs::path meta = folder / "metadata.yaml";
  if (!fs::exists(meta)) return filesWithoutMetadata(folder);
  BagFiles out;
  try {
    const YAML::Node info = YAML::LoadFile(meta.string())["rosbag2_bagfile_information"];
    if (!info) fail(meta, "no rosbag2_bagfile_information");
    out.storage = info["storage_identifier"].as<std::string>("sqlite3");
    const std::string compression = info["compression_format"].as<std::string>("");
    if (!compression.empty())
      fail(meta, "compressed bag (" + shownText(compression) +
                     "); decompress it with `ros2 bag convert`");
    for (const auto& f : info["relative_file_paths"]) {
      // folder / "/x.db3" would be /x.db3: a path outside the bag, named without it.
      const fs::path file = f.as<std::string>();
      if (file.empty() || file.is_absolute())
        fail(meta, "relative_file_paths: '" + shownText(file.string()) +
                       "' is not a path relative to the bag folder");
      out.files.push_back(folder / file);
    }
  } catch (const YAML::Exception& e) {
    fail(meta, "not a readable bag description (" + shownText(e.what(), 200) + ")");
  }
  if (out.storage != "sqlite3" && out.storage != "mcap")
    fail(meta, "storage '" + shownText(out.storage) + "' is not read (sqlite3, mcap)");
  if (out.files.empty()) fail(meta, "relative_file_paths lists no file");
  return out;
}

class Ros2Bag : public BagStorage {
 public:
  explicit Ros2Bag(const fs::path& path) {
    const std::vector<fs::path> files =
        fs::is_directory(path) ? bagFiles(path).files : std::vector{path};
    for (const fs::path& f : files) {
      if (!fs::exists(f)) fail(f, "missing (listed in metadata.yaml)");
      dbs_.push_back(std::make_unique<Database>(f));
      readTopics(dbs_.size() - 1);
    }
    path_ = files.front();
  }
  const fs::path& path() const override { return path_; }
  const std::vector<BagTopic>& topics() const override { return topics_; }
  std::vector<MessageRef> messages(const std::string& topic) override;
  SerializedMessage read(const std::string& topic, const MessageRef& ref) override {
    return readBytes(topic, ref, "SELECT data FROM messages WHERE id = ?", -1);
  }
  SerializedMessage readPrefix(const std::string& topic, const MessageRef& ref,
                               size_t max_bytes) override {
    return readBytes(topic, ref, "SELECT substr(data, 1, ?) FROM messages WHERE id = ?",
                     static_cast<int64_t>(max_bytes));
  }

 private:
  void readTopics(size_t file);
  SerializedMessage readBytes(const std::string& topic, const MessageRef& ref, const char* sql,
                              int64_t prefix);

  fs::path path_;
  std::vector<std::unique_ptr<Database>> dbs_;
  std::vector<BagTopic> topics_;
  // Per topic name, its id and serialization in each file (a split bag numbers topics per file).
  std::map<std::string, std::map<size_t, TopicInFile>> ids_;
};

void Ros2Bag::readTopics(size_t file) {
  const Database& db = *dbs_[file];
  Stmt s = db.prepare("SELECT id, name, type, serialization_format FROM topics");
  while (db.step(s.get())) {
    auto text = [&](int col) {
      const unsigned char* t = sqlite3_column_text(s.get(), col);
      return t ? std::string(reinterpret_cast<const char*>(t)) : std::string();
    };
    const std::string name = text(1);
    ids_[name][file] = TopicInFile{sqlite3_column_int64(s.get(), 0), text(3)};
    auto it = std::find_if(topics_.begin(), topics_.end(),
                           [&](const BagTopic& t) { return t.name == name; });
    if (it == topics_.end())
      it = topics_.insert(topics_.end(), BagTopic{name, normaliseTypeName(text(2)), 0});
    Stmt count = db.prepare("SELECT COUNT(*) FROM messages WHERE topic_id = ?");
    sqlite3_bind_int64(count.get(), 1, ids_[name][file].id);
    if (db.step(count.get()))
      it->count += static_cast<size_t>(sqlite3_column_int64(count.get(), 0));
  }
}

std::vector<MessageRef> Ros2Bag::messages(const std::string& topic) {
  std::vector<MessageRef> refs;
  auto found = ids_.find(topic);
  if (found == ids_.end()) return refs;
  for (const auto& [file, t] : found->second) {
    const Database& db = *dbs_[file];
    if (t.serialization != "cdr")
      fail(db.file(), "topic " + shownText(topic) + " is serialized as '" +
                          shownText(t.serialization) + "'; only cdr is read");
    Stmt s =
        db.prepare("SELECT id, timestamp FROM messages WHERE topic_id = ? ORDER BY timestamp, id");
    sqlite3_bind_int64(s.get(), 1, t.id);
    while (db.step(s.get()))
      refs.push_back(MessageRef{sqlite3_column_int64(s.get(), 1) * 1e-9, file,
                                sqlite3_column_int64(s.get(), 0)});
  }
  std::stable_sort(refs.begin(), refs.end(),
                   [](const MessageRef& a, const MessageRef& b) { return a.time_s < b.time_s; });
  return refs;
}

SerializedMessage Ros2Bag::readBytes(const std::string& topic, const MessageRef& ref,
                                     const char* sql, int64_t prefix) {
  const Database& db = *dbs_.at(ref.file);
  Stmt s = db.prepare(sql);
  int arg = 1;
  if (prefix >= 0) sqlite3_bind_int64(s.get(), arg++, prefix);
  sqlite3_bind_int64(s.get(), arg, ref.row);
  if (!db.step(s.get()))
    fail(db.file(), "message " + std::to_string(ref.row) + " on " + shownText(topic) + " is gone");
  const void* data = sqlite3_column_blob(s.get(), 0);
  const int size = sqlite3_column_bytes(s.get(), 0);
  SerializedMessage m;
  m.bytes.assign(static_cast<const char*>(data), static_cast<size_t>(size));
  m.format = WireFormat::kCdr;
  m.file = db.file();
  m.topic = topic;
  return m;
}

}  // namespace

std::unique_ptr<BagStorage> openRos2Bag(const std::filesystem::path& db3_or_folder) {
  if (fs::is_directory(db3_or_folder)) {
    const BagFiles bag = bagFiles(db3_or_folder);
    if (bag.storage == "mcap") {
      if (bag.files.size() != 1)
        fail(db3_or_folder, "a split MCAP bag (" + std::to_string(bag.files.size()) +
                                " files) is not read; give one of its .mcap files");
      return openMcapBag(bag.files.front());
    }
  }
  return std::make_unique<Ros2Bag>(db3_or_folder);
}

}  // namespace semsegmap::rosmsg
