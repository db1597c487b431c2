// Unit tests of the SQLite connection's statement cache: a statement taken from the cache behaves like a
// freshly prepared one (no bindings left, first row again), and one SQL text can be in use twice at once.
#include <gtest/gtest.h>

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

}  // namespace
}  // namespace balloon::store
