// Thin RAII wrappers over the SQLite C API, shared by the run-file writer and
// reader and by the analysis: every failure is an InputError naming the file.
// (SQLite's own header is light; nothing heavy leaks through here.)
#pragma once

#include <sqlite3.h>

#include <cmath>
#include <cstdint>
#include <string>

#include "crowdrecon/common/error.hpp"

namespace crowdrecon::sqlite {

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

 private:
  void Check(int rc) const {
    if (rc != SQLITE_OK) Fail();
  }
  [[noreturn]] void Fail() const { throw InputError(db_.file() + ": SQLite error: " + sqlite3_errmsg(db_.get())); }
  const Database& db_;
  sqlite3_stmt* stmt_ = nullptr;
};

}  // namespace crowdrecon::sqlite
