// Thin RAII wrappers over the SQLite C API, shared by the run-file writer and
// reader and by the analysis: every failure is an InputError naming the file.
// (SQLite's own header is light; nothing heavy leaks through here.)
#pragma once

#include <sqlite3.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::sqlite {

// Removes the journal, write-ahead log and shared-memory files that a
// killed writer may have left beside `file` ("-journal", "-wal", "-shm"):
// a writer that replaces `file` calls it first, or SQLite would apply the
// old log to the new file. Returns the names removed.
inline std::vector<std::string> RemoveSidecars(const std::filesystem::path& file) {
  std::vector<std::string> removed;
  for (const char* suffix : {"-journal", "-wal", "-shm"}) {
    const std::filesystem::path side = file.string() + suffix;
    std::error_code ec;
    if (std::filesystem::exists(std::filesystem::symlink_status(side, ec)) && std::filesystem::remove(side, ec))
      removed.push_back(side.string());
  }
  return removed;
}

class Database {
 public:
  Database(const std::string& file, int flags) : file_(file) {
    if (sqlite3_open_v2(file_.c_str(), &db_, flags, nullptr) != SQLITE_OK) {
      const std::string message = db_ ? sqlite3_errmsg(db_) : "out of memory";
      sqlite3_close(db_);
      db_ = nullptr;
      throw InputError(file_ + ": cannot open run file: " + message);
    }
    // A run being simulated commits a frame at a time; readers wait for the
    // writer's transaction rather than fail.
    sqlite3_busy_timeout(db_, 10000);
  }
  ~Database() {
    if (db_) sqlite3_close(db_);
  }
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  void Exec(const std::string& sql) const {
    char* error = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
      const std::string message = error ? error : "unknown error";
      sqlite3_free(error);
      throw InputError(file_ + ": SQLite error: " + message + " (in: " + sql.substr(0, 80) + ")");
    }
  }
  sqlite3* get() const { return db_; }
  const std::string& file() const { return file_; }

 private:
  std::string file_;
  sqlite3* db_ = nullptr;
};

class Statement {
 public:
  Statement(const Database& db, const std::string& sql) : db_(db) {
    if (sqlite3_prepare_v2(db.get(), sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK)
      throw InputError(db.file() + ": SQLite error: " + sqlite3_errmsg(db.get()) + " (in: " + sql.substr(0, 80) + ")");
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  // NaN is bound as NULL: SQLite has no NaN, and NULL says "no value".
  Statement& Bind(int i, double v) {
    Check(!std::isnan(v) ? sqlite3_bind_double(stmt_, i, v) : sqlite3_bind_null(stmt_, i));
    return *this;
  }
  Statement& Bind(int i, std::int64_t v) {
    Check(sqlite3_bind_int64(stmt_, i, v));
    return *this;
  }
  Statement& Bind(int i, const std::string& v) {
    Check(sqlite3_bind_text(stmt_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& BindBlob(int i, const std::string& bytes) {
    Check(sqlite3_bind_blob(stmt_, i, bytes.data(), static_cast<int>(bytes.size()), SQLITE_TRANSIENT));
    return *this;
  }
  Statement& BindNull(int i) {
    Check(sqlite3_bind_null(stmt_, i));
    return *this;
  }
  void Run() {
    const int rc = sqlite3_step(stmt_);
    if (rc != SQLITE_DONE) Fail();
    sqlite3_reset(stmt_);
  }
  bool Next() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc != SQLITE_DONE) Fail();
    return false;
  }
  // Names the rows of this query in messages about bad values: the table, and
  // the columns (by index) that identify a row. A column whose name is
  // qualified ("person_state.vel_x", an SQL alias) names its own table.
  Statement& Describe(std::string table, std::vector<int> key_columns) {
    table_ = std::move(table);
    key_columns_ = std::move(key_columns);
    return *this;
  }
  // A number in [min, max] from column `col`. Text, NULL, a blob, NaN or a
  // value out of range is a corrupted file: an InputError naming the file,
  // table, row and column, the value and the range.
  double Real(int col, double min, double max) const {
    const int type = Type(col);
    const double v = Double(col);
    if ((type != SQLITE_FLOAT && type != SQLITE_INTEGER) || !(v >= min && v <= max))
      BadValue(col, type, "a number in [" + FormatNumber(min) + ", " + FormatNumber(max) + "]");
    return v;
  }
  // A whole number in [min, max] from column `col` (checked as Real is).
  std::int64_t Integer(int col, std::int64_t min, std::int64_t max) const {
    const int type = Type(col);  // before any conversion by the reads below
    const std::int64_t v = Int(col);
    if (type != SQLITE_INTEGER || v < min || v > max)
      BadValue(col, type, "a whole number in [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    return v;
  }
  double Double(int col) const { return sqlite3_column_double(stmt_, col); }
  std::int64_t Int(int col) const { return sqlite3_column_int64(stmt_, col); }
  // SQLITE_INTEGER, SQLITE_FLOAT, SQLITE_TEXT, SQLITE_BLOB or SQLITE_NULL.
  int Type(int col) const { return sqlite3_column_type(stmt_, col); }
  int ColumnCount() const { return sqlite3_column_count(stmt_); }
  std::string ColumnName(int col) const { return sqlite3_column_name(stmt_, col); }
  std::string Text(int col) const {
    const auto* t = sqlite3_column_text(stmt_, col);
    return t ? reinterpret_cast<const char*>(t) : "";
  }
  // The bytes of a blob column (empty for NULL); valid until the next step.
  std::pair<const unsigned char*, std::size_t> Blob(int col) const {
    const auto* b = static_cast<const unsigned char*>(sqlite3_column_blob(stmt_, col));
    const int n = sqlite3_column_bytes(stmt_, col);
    return {b, b ? static_cast<std::size_t>(n) : 0};
  }

 private:
  void Check(int rc) const {
    if (rc != SQLITE_OK) Fail();
  }
  [[noreturn]] void Fail() const { throw InputError(db_.file() + ": SQLite error: " + sqlite3_errmsg(db_.get())); }
  // `type`: the column's type as read before any conversion.
  [[noreturn]] void BadValue(int col, int type, const std::string& expected) const {
    std::string table = table_, column = ColumnName(col);
    if (const auto dot = column.find('.'); dot != std::string::npos) {
      table = column.substr(0, dot);
      column = column.substr(dot + 1);
    }
    std::string row;
    for (int k : key_columns_) row += (row.empty() ? "" : ", ") + ColumnName(k) + " " + ShortText(Text(k), 24);
    static constexpr const char* kTypes[] = {"", "integer", "real", "text", "blob", "NULL"};
    const std::string found = type == SQLITE_NULL ? "NULL"
                              : type == SQLITE_BLOB ? "a blob"
                                                    : std::string(kTypes[type]) + " " + ShortText(Text(col), 40);
    throw InputError(db_.file() + ": table " + table + (row.empty() ? "" : ", row " + row) + ", column " + column +
                     ": found " + found + "; expected " + expected + " (the run file is damaged or was not written by crowdrecon)");
  }
  const Database& db_;
  sqlite3_stmt* stmt_ = nullptr;
  std::string table_ = "?";
  std::vector<int> key_columns_;
};

// Whether the database has a table of this name.
inline bool HasTable(const Database& db, const std::string& name) {
  Statement s(db, "SELECT COUNT(*) FROM sqlite_master WHERE type = 'table' AND name = ?");
  s.Bind(1, name);
  return s.Next() && s.Int(0) > 0;
}

// Inserts rows of numbers into one table, many rows per INSERT statement
// ("INSERT INTO t VALUES (?, ...), (?, ...), ..."): per row, SQLite then
// skips a statement's start, its cursors' opening and closing, and its reset,
// which cost more than the row itself (a 10,000-person frame: about half the
// time of single-row inserts). Add a row's values in column order; Finish
// inserts the rows still held (call it before committing). Keep the object
// for the next batch: its statements (one per number of rows) stay prepared.
class BatchInsert {
 public:
  static constexpr std::size_t kRowsPerStatement = 64;

  BatchInsert(const Database& db, std::string table, int columns)
      : db_(db), table_(std::move(table)), columns_(static_cast<std::size_t>(columns)) {
    values_.reserve(kRowsPerStatement * columns_);
  }
  BatchInsert& Add(std::int64_t v) { return Push({true, v, 0.0}); }
  BatchInsert& Add(double v) { return Push({false, 0, v}); }
  void Finish() {
    if (!values_.empty()) Insert();
  }
  // Drops rows added but not inserted (after a failure).
  void Discard() { values_.clear(); }

 private:
  struct Value {
    bool integer;
    std::int64_t i;
    double d;
  };
  BatchInsert& Push(Value v) {
    values_.push_back(v);
    if (values_.size() == kRowsPerStatement * columns_) Insert();
    return *this;
  }
  std::string Sql(std::size_t rows) const {
    std::string row = "(";
    for (std::size_t c = 0; c < columns_; ++c) row += c == 0 ? "?" : ", ?";
    row += ")";
    std::string sql = "INSERT INTO " + table_ + " VALUES ";
    for (std::size_t r = 0; r < rows; ++r) sql += (r == 0 ? "" : ", ") + row;
    return sql;
  }
  void Insert() {
    if (values_.size() % columns_ != 0)
      throw InputError(db_.file() + ": internal error: incomplete row for table " + table_);
    const std::size_t rows = values_.size() / columns_;
    std::unique_ptr<Statement>& prepared = statements_[rows - 1];
    if (!prepared) prepared = std::make_unique<Statement>(db_, Sql(rows));
    Statement* statement = prepared.get();
    for (std::size_t k = 0; k < values_.size(); ++k) {
      const int index = static_cast<int>(k) + 1;
      if (values_[k].integer) {
        statement->Bind(index, values_[k].i);
      } else {
        statement->Bind(index, values_[k].d);
      }
    }
    statement->Run();
    values_.clear();
  }

  const Database& db_;
  std::string table_;
  std::size_t columns_;
  std::vector<Value> values_;
  std::unique_ptr<Statement> statements_[kRowsPerStatement];  // [rows - 1]
};

}  // namespace crowdrecon::sqlite
