// api::Lru, the one least-recently-used container behind every cache of the daemon (the content
// stores, the decoded scenes and images, the GPU scenes, the derived data): recency order, byte
// accounting, and eviction that spares what the caller keeps and hands over what it removes.
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "api/Lru.h"

namespace radiant::api {
namespace {

using L = Lru<std::string, int>;

std::vector<std::string> keys(const L& l) {
  std::vector<std::string> out;
  for (const auto& e : l) out.push_back(e.key);
  return out;
}

TEST(Lru, UseMovesAnEntryToTheFrontAndPutReplacesByKey) {
  L l;
  l.put("a", 1, 10);
  l.put("b", 2, 20);
  l.put("c", 3, 30);
  EXPECT_EQ(keys(l), (std::vector<std::string>{"c", "b", "a"}));
  EXPECT_EQ(l.bytes(), 60u);
  ASSERT_NE(l.use("a"), nullptr);
  EXPECT_EQ(*l.use("a"), 1);
  EXPECT_EQ(keys(l), (std::vector<std::string>{"a", "c", "b"}));
  EXPECT_EQ(l.use("z"), nullptr);
  EXPECT_EQ(l.find("b"), std::next(l.begin(), 2));  // find does not reorder
  EXPECT_EQ(keys(l), (std::vector<std::string>{"a", "c", "b"}));
  l.put("c", 33, 5);  // replaced: one entry, its new size, in front
  EXPECT_EQ(keys(l), (std::vector<std::string>{"c", "a", "b"}));
  EXPECT_EQ(l.size(), 3u);
  EXPECT_EQ(l.bytes(), 35u);
  EXPECT_EQ(*l.use("c"), 33);
  l.put("old", 0, 1, /*leastRecent=*/true);
  EXPECT_EQ(keys(l).back(), "old");
  l.resize(l.find("old"), 101);
  EXPECT_EQ(l.bytes(), 136u);
  EXPECT_TRUE(l.erase("old"));
  EXPECT_FALSE(l.erase("old"));
  EXPECT_EQ(l.bytes(), 35u);
  l.clear();
  EXPECT_TRUE(l.empty());
  EXPECT_EQ(l.bytes(), 0u);
}

TEST(Lru, EvictionGoesFromTheLeastRecentlyUsedSparingKeptEntries) {
  L l;
  for (int i = 0; i < 5; ++i) l.put(std::to_string(i), i, 10);  // "0" least recently used
  std::vector<std::string> evicted;
  // Down to 20 bytes, sparing "1": "0", "2" and "3" go, in that order; "1" and "4" stay.
  const std::size_t n = l.evict([](const L& x) { return x.bytes() > 20; },
                                [](const L::Entry& e) { return e.key == "1"; },
                                [&](L::Entry&& e) { evicted.push_back(e.key); });
  EXPECT_EQ(n, 3u);
  EXPECT_EQ(evicted, (std::vector<std::string>{"0", "2", "3"}));
  EXPECT_EQ(keys(l), (std::vector<std::string>{"4", "1"}));
  EXPECT_EQ(l.bytes(), 20u);
  // Evicted keys are gone from the index: they can be stored again.
  EXPECT_EQ(l.use("2"), nullptr);
  l.put("2", 2, 10);
  EXPECT_EQ(keys(l), (std::vector<std::string>{"2", "4", "1"}));
  // When everything left is kept, eviction stops short of its goal instead of looping.
  EXPECT_EQ(l.evict([](const L&) { return true; }, [](const L::Entry&) { return true; }, [](L::Entry&&) {}), 0u);
  EXPECT_EQ(l.size(), 3u);
  // By count.
  l.evict([](const L& x) { return x.size() > 1; });
  EXPECT_EQ(keys(l), (std::vector<std::string>{"2"}));
}

TEST(Lru, EvictedValuesAreHandedOverNotDestroyedInside) {
  Lru<int, std::shared_ptr<int>> l;
  auto held = std::make_shared<int>(7);
  l.put(1, held);
  l.put(2, std::make_shared<int>(8));
  std::vector<std::shared_ptr<int>> out;
  // Entries someone else holds (use_count > 1) are kept, as the decoded-scene cache does.
  l.evict([](const auto& x) { return !x.empty(); }, [](const auto& e) { return e.value.use_count() > 1; },
          [&](auto&& e) { out.push_back(std::move(e.value)); });
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(*out[0], 8);
  EXPECT_EQ(l.size(), 1u);
  EXPECT_EQ(*l.use(1)->get(), 7);
}

}  // namespace
}  // namespace radiant::api
