// ROS 2 SQLite bags (.db3): table `topics` (id, name, type, serialization_format, ...) and table
// `messages` (id, topic_id, timestamp in ns, data = the serialized message, "cdr" for ROS 2).
// Opened read-only; messages are walked with one query ordered by timestamp.

#include <sqlite3.h>

#include <map>

#include "scanmatch/io/bag/bag_detail.hpp"

namespace scanmatch::bag_detail {
namespace {

struct CloseDb {
  void operator()(sqlite3* db) const { sqlite3_close(db); }
};
struct Finalize {
  void operator()(sqlite3_stmt* statement) const { sqlite3_finalize(statement); }
};
using Statement = std::unique_ptr<sqlite3_stmt, Finalize>;

class Db3Bag : public BagReader {
 public:
  explicit Db3Bag(const std::string& path) {
    path_ = path;
    sqlite3* db = nullptr;
    const int opened = sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr);
    db_.reset(db);
    if (opened != SQLITE_OK) fail_sql("cannot open");
    const Statement statement = prepare("SELECT id, name, type, serialization_format FROM topics");
    std::map<std::string, BagTopic> by_name;
    int status;
    sqlite3_stmt* topics = statement.get();
    while ((status = sqlite3_step(topics)) == SQLITE_ROW) {
      BagTopic t;
      t.name = text(topics, 1);
      t.type = text(topics, 2);
      t.encoding = text(topics, 3);
      ids_.emplace(sqlite3_column_int64(topics, 0), t.name);
      by_name.emplace(t.name, std::move(t));
    }
    if (status != SQLITE_DONE) fail_sql("cannot read the topics table");
    const Statement count_statement =
        prepare("SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id");
    sqlite3_stmt* counts = count_statement.get();
    while ((status = sqlite3_step(counts)) == SQLITE_ROW) {
      const auto id = ids_.find(sqlite3_column_int64(counts, 0));
      if (id == ids_.end())
        fail(path_, "table messages refers to topic id " +
                        std::to_string(sqlite3_column_int64(counts, 0)) +
                        " that table topics lacks");
      by_name[id->second].message_count +=
          static_cast<std::uint64_t>(sqlite3_column_int64(counts, 1));
    }
    if (status != SQLITE_DONE) fail_sql("cannot count the messages");
    for (auto& [name, t] : by_name) topics_.push_back(std::move(t));
    select({});
  }

  std::string format() const override { return "ROS 2 SQLite bag"; }

  void select(const std::vector<std::string>& names) override {
    check_topics(names);
    // Sorting only the small columns: the blobs are fetched by id (the table's key) one by one,
    // so a large bag is not copied through SQLite's sorter.
    std::string sql = "SELECT id, topic_id, timestamp FROM messages";
    std::string ids;
    for (const auto& [id, name] : ids_)
      for (const std::string& wanted : names)
        if (name == wanted) {
          if (!ids.empty()) ids += ',';
          ids += std::to_string(id);
        }
    if (!names.empty()) {
      sql += " WHERE topic_id IN (";
      sql += ids;
      sql += ')';
    }
    sql += " ORDER BY timestamp, id";
    query_.reset();
    query_ = prepare(sql.c_str());
    if (!data_) data_ = prepare("SELECT data FROM messages WHERE id = ?");
  }

  bool next(BagMessage& message) override {
    const int status = sqlite3_step(query_.get());
    if (status == SQLITE_DONE) return false;
    if (status != SQLITE_ROW) fail_sql("cannot read the messages table");
    const std::int64_t row = sqlite3_column_int64(query_.get(), 0);
    const auto id = ids_.find(sqlite3_column_int64(query_.get(), 1));
    if (id == ids_.end()) fail(path_, "message row " + std::to_string(row), "unknown topic id");
    const BagTopic& topic = *find_topic(id->second);
    message.timestamp_ns = sqlite3_column_int64(query_.get(), 2);
    message.topic = topic.name;
    message.type = topic.type;
    message.encoding = topic.encoding;
    sqlite3_reset(data_.get());
    sqlite3_bind_int64(data_.get(), 1, row);
    if (sqlite3_step(data_.get()) != SQLITE_ROW)
      fail_sql("cannot read message row " + std::to_string(row));
    const void* blob = sqlite3_column_blob(data_.get(), 0);
    const int size = sqlite3_column_bytes(data_.get(), 0);
    message.data.assign(static_cast<const char*>(blob), blob ? static_cast<std::size_t>(size) : 0);
    message.where = "message row " + std::to_string(row);
    return true;
  }

 private:
  [[noreturn]] void fail_sql(const std::string& what) const {
    fail(path_, what + ": " + (db_ ? sqlite3_errmsg(db_.get()) : "out of memory"));
  }
  Statement prepare(const char* sql) const {
    sqlite3_stmt* statement = nullptr;
    const int status = sqlite3_prepare_v2(db_.get(), sql, -1, &statement, nullptr);
    Statement owned(statement);
    if (status != SQLITE_OK) fail_sql("not a ROS 2 bag (query failed)");
    return owned;
  }
  static std::string text(sqlite3_stmt* statement, int column) {
    const unsigned char* s = sqlite3_column_text(statement, column);
    return s ? reinterpret_cast<const char*>(s) : "";
  }

  std::unique_ptr<sqlite3, CloseDb> db_;
  Statement query_, data_;
  std::map<std::int64_t, std::string> ids_;
};

}  // namespace

std::unique_ptr<BagReader> open_db3(const std::string& path) {
  return std::make_unique<Db3Bag>(path);
}

}  // namespace scanmatch::bag_detail
