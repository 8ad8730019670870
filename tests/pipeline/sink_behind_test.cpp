// SinkBehind (g2s/sink_behind.hpp): the next sink gets the very calls, in the very order, that it
// would get directly, never two at once, with positions copied (the caller's buffers are
// overwritten right after each call); blocks and finish come after every call before them; an
// exception the next sink throws on the playing thread comes back to the caller, and no call
// after it reaches the next sink.
#include "g2s/sink_behind.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace g2s {
namespace {

// Logs every call as text; fails the test if two calls overlap. throw_at: the number of the
// triangle call that throws (0: none).
class RecordingSink final : public MeshSink {
 public:
  explicit RecordingSink(std::size_t throw_at = 0) : throw_at_(throw_at) {}
  void vertex(Index id, const double xyz[3]) override {
    const Enter enter(*this);
    log.push_back("v " + std::to_string(id) + " " + text(xyz));
  }
  void triangle(const Triangle& corners, const std::array<const double*, 3>& xyz,
                std::uint32_t group) override {
    const Enter enter(*this);
    if (++triangles_ == throw_at_) throw std::runtime_error("disk full");
    log.push_back("t " + std::to_string(corners[0]) + " " + std::to_string(corners[1]) + " " +
                  std::to_string(corners[2]) + " " + text(xyz[0]) + text(xyz[1]) + text(xyz[2]) +
                  " g" + std::to_string(group));
  }
  void vertex_done(std::uint32_t vertex) override {
    const Enter enter(*this);
    log.push_back("d " + std::to_string(vertex));
  }
  std::unique_ptr<SinkBlockWork> prepare(const SinkBlock& block) const override {
    return block.triangles.empty() ? nullptr : std::make_unique<SinkBlockWork>();
  }
  void block(const SinkBlock& block, std::uint32_t first_vertex, std::uint32_t first_group,
             std::unique_ptr<SinkBlockWork> work) override {
    const Enter enter(*this);
    log.push_back("b " + std::to_string(block.triangles.size()) + " " +
                  std::to_string(first_vertex) + " " + std::to_string(first_group) +
                  (work ? " prepared" : ""));
  }
  void finish(std::span<const std::uint8_t> flip) override {
    const Enter enter(*this);
    log.push_back("f " + std::to_string(flip.size()));
  }

  std::vector<std::string> log;
  std::atomic<bool> overlapped{false};

 private:
  struct Enter {
    explicit Enter(RecordingSink& sink) : sink_(sink) {
      if (sink_.inside_.exchange(true)) sink_.overlapped = true;
    }
    ~Enter() { sink_.inside_ = false; }
    RecordingSink& sink_;
  };
  static std::string text(const double* xyz) {
    return std::to_string(xyz[0]) + "," + std::to_string(xyz[1]) + "," + std::to_string(xyz[2]);
  }
  std::atomic<bool> inside_{false};
  std::size_t throw_at_;
  std::size_t triangles_ = 0;
};

// Several batches' worth of calls with blocks among them, as the stitcher makes them: each
// position given from a buffer that is overwritten once the call returns.
void stream(MeshSink& sink) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> coordinate(-1, 1);
  const std::vector<Triangle> block_triangles = {{0, 1, 2}, {2, 1, 3}};
  const std::vector<Index> block_ids = {7, 8, 9, 10};
  const std::vector<double> block_xyz(12, 0.5);
  const std::vector<std::uint32_t> block_group = {0, 0};
  const SinkBlock block{block_ids, block_xyz, block_triangles, block_group, {}};
  double xyz[3][3];
  std::uint32_t vertices = 0;
  for (int call = 0; call < 3 * static_cast<int>(SinkBehind::kBatchCalls) + 17; ++call) {
    if (call % 2500 == 1000) {
      sink.block(block, vertices, 3, sink.prepare(block));
      vertices += 4;
      continue;
    }
    for (auto& corner : xyz) {
      for (double& c : corner) c = coordinate(rng);
    }
    switch (call % 3) {
      case 0:
        sink.vertex(static_cast<Index>(call), xyz[0]);
        ++vertices;
        break;
      case 1:
        sink.triangle({vertices - 1, vertices - 1, vertices - 1}, {xyz[0], xyz[1], xyz[2]},
                      static_cast<std::uint32_t>(call % 7));
        break;
      default:
        sink.vertex_done(vertices - 1);
    }
    for (auto& corner : xyz) {
      for (double& c : corner) c = -9;  // the caller's buffer, reused
    }
  }
  const std::vector<std::uint8_t> flip(5, 0);
  sink.finish(flip);
}

TEST(SinkBehind, TheNextSinkGetsTheSameCallsInTheSameOrderOneAtATime) {
  RecordingSink direct;
  stream(direct);
  RecordingSink behind_next;
  {
    SinkBehind behind(behind_next);
    stream(behind);
    EXPECT_GE(behind.cpu_seconds(), 0.0);
  }
  ASSERT_GT(direct.log.size(), 3 * SinkBehind::kBatchCalls);
  EXPECT_EQ(behind_next.log, direct.log);
  EXPECT_FALSE(behind_next.overlapped);
  EXPECT_EQ(behind_next.log.back(), "f 5");
}

TEST(SinkBehind, AnExceptionOfTheNextSinkReachesTheCallerAndStopsTheCalls) {
  RecordingSink next(/*throw_at=*/3000);
  SinkBehind behind(next);
  EXPECT_THROW(stream(behind), std::runtime_error);
  // Calls up to the throwing one were played, none after it.
  std::size_t triangles = 0;
  for (const std::string& line : next.log) triangles += line[0] == 't';
  EXPECT_EQ(triangles, 2999u);
  EXPECT_NE(next.log.back()[0], 'f');
  // Later calls throw again and reach nothing.
  const std::size_t logged = next.log.size();
  const std::vector<std::uint8_t> flip;
  EXPECT_THROW(behind.finish(flip), std::runtime_error);
  EXPECT_EQ(next.log.size(), logged);
}

}  // namespace
}  // namespace g2s
