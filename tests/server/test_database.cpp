// Unit tests of the SQLite connection: a statement taken from the cache behaves like a freshly prepared
// one (no bindings left, first row again), one SQL text can be in use twice at once, and the WAL's page
// count (which decides when the store checkpoints) falls back after a checkpoint.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "scratch_dir.hpp"
#include "store/database.hpp"

namespace balloon::store {
namespace {

void fill_numbers(Database& database, int count) {
  database.execute("CREATE TABLE numbers (n INTEGER)");
  Transaction transaction(database);
  for (int n = 1; n <= count; ++n) database.prepare("INSERT INTO numbers (n) VALUES (?)").bind(1, n).run();
  transaction.commit();
}

TEST(Database, AStatementFromTheCacheHasNoBindingsLeft) {
  Database database(":memory:");
  {
    Statement first = database.prepare("SELECT ?");
    first.bind(1, 42);
    ASSERT_TRUE(first.step());
    EXPECT_EQ(first.column_int(0), 42);
  }
  Statement again = database.prepare("SELECT ?");
  ASSERT_TRUE(again.step());
  EXPECT_TRUE(again.column_is_null(0));
}

TEST(Database, AStatementLeftMidwayStartsAgainFromTheFirstRow) {
  Database database(":memory:");
  fill_numbers(database, 5);
  const char* sql = "SELECT n FROM numbers ORDER BY n";
  {
    Statement partly = database.prepare(sql);
    ASSERT_TRUE(partly.step());
    ASSERT_TRUE(partly.step());
    EXPECT_EQ(partly.column_int(0), 2);
  }
  // Its read is over: a write transaction starts, and the next use reads from the top.
  Transaction transaction(database);
  database.prepare("INSERT INTO numbers (n) VALUES (6)").run();
  transaction.commit();
  Statement again = database.prepare(sql);
  int rows = 0;
  while (again.step()) EXPECT_EQ(again.column_int(0), ++rows);
  EXPECT_EQ(rows, 6);
}

TEST(Database, OneSqlTextCanBeInUseTwiceAtOnce) {
  Database database(":memory:");
  fill_numbers(database, 3);
  const char* sql = "SELECT n FROM numbers WHERE n >= ? ORDER BY n";
  int pairs = 0;
  Statement outer = database.prepare(sql);
  outer.bind(1, 1);
  while (outer.step()) {
    Statement inner = database.prepare(sql);  // the cached one is taken: this is a second statement
    inner.bind(1, outer.column_int(0));
    while (inner.step()) ++pairs;
  }
  EXPECT_EQ(pairs, 3 + 2 + 1);
}

TEST(Database, TheWalPageCountFallsBackAfterACheckpointWhereTheWalFileDoesNot) {
  balloon::testing::ScratchDir scratch("balloon-wal");
  const std::string path = scratch.file("store.db");
  Database writer(path, 5000, Synchronous::Normal);
  writer.execute("PRAGMA wal_autocheckpoint = 0; CREATE TABLE blobs (b BLOB)");
  writer.count_wal_frames();
  const std::string half_megabyte(512 * 1024, 'x');
  writer.prepare("INSERT INTO blobs (b) VALUES (?)").bind_blob(1, half_megabyte).run();
  EXPECT_GE(writer.wal_frames(), 128);  // 4 KB pages
  {
    Database checkpointer(path, 5000, Synchronous::Normal);
    checkpointer.execute("PRAGMA wal_checkpoint(PASSIVE)");
  }
  writer.prepare("INSERT INTO blobs (b) VALUES (?)").bind_blob(1, std::string("small")).run();
  EXPECT_LE(writer.wal_frames(), 4);
  // The file keeps its size (the log starts over inside it): not a measure of what is still to copy.
  EXPECT_GE(std::filesystem::file_size(path + "-wal"), 512u * 1024u);
}

}  // namespace
}  // namespace balloon::store
