// Range coder and model round trips on random and skewed streams.
#include <gtest/gtest.h>

#include <random>

#include "entropy/models.h"
#include "entropy/range_coder.h"
#include "entropy/static_tables.h"

namespace pomar {
namespace {

struct Op {
  int kind; // 0 frequency symbol, 1 bit, 2 bypass, 3 small value, 4 residual
  int64_t value;
  int nbits;
};

std::vector<Op> random_ops(uint32_t seed, size_t n, bool skewed) {
  std::mt19937 rng(seed);
  std::vector<Op> ops;
  std::geometric_distribution<int> geo(skewed ? 0.7 : 0.1);
  for (size_t i = 0; i < n; ++i) {
    Op op{int(rng() % 5), 0, 0};
    switch (op.kind) {
    case 0:
      op.value = skewed ? std::min(geo(rng), 11) : int(rng() % 12);
      break;
    case 1:
      op.value = skewed ? (rng() % 50 == 0) : int(rng() & 1);
      break;
    case 2:
      op.nbits = 1 + int(rng() % 24);
      op.value = rng() & ((1u << op.nbits) - 1);
      break;
    case 3:
      op.value = skewed ? geo(rng) : int64_t(rng() % 100000);
      break;
    case 4:
      op.value = (skewed ? geo(rng) : int64_t(rng() % (1u << 26))) * (rng() & 1 ? -1 : 1);
      break;
    }
    ops.push_back(op);
  }
  return ops;
}

void roundtrip(const std::vector<Op> &ops) {
  std::vector<uint8_t> bytes;
  {
    RangeEncoder enc(&bytes);
    FrequencyModel fm(12);
    BitModel bm;
    FrequencyModel small(kSmallSymbols + 1);
    GeometryModels g;
    for (const Op &op : ops) {
      switch (op.kind) {
      case 0:
        enc.encode(fm, int(op.value));
        break;
      case 1:
        enc.encode_bit(bm, int(op.value));
        break;
      case 2:
        enc.encode_bypass(uint32_t(op.value), op.nbits);
        break;
      case 3:
        put_small(enc, small, uint32_t(op.value));
        break;
      case 4:
        put_residual(enc, g, 1, 7, op.value);
        break;
      }
    }
    enc.finish();
  }
  RangeDecoder dec(bytes.data(), bytes.size());
  FrequencyModel fm(12);
  BitModel bm;
  FrequencyModel small(kSmallSymbols + 1);
  GeometryModels g;
  for (size_t i = 0; i < ops.size(); ++i) {
    const Op &op = ops[i];
    int64_t got = 0;
    switch (op.kind) {
    case 0:
      got = dec.decode(fm);
      break;
    case 1:
      got = dec.decode_bit(bm);
      break;
    case 2:
      got = dec.decode_bypass(op.nbits);
      break;
    case 3:
      got = get_small(dec, small);
      break;
    case 4:
      got = get_residual(dec, g, 1, 7);
      break;
    }
    ASSERT_EQ(got, op.value) << "operation " << i << " kind " << op.kind;
  }
  EXPECT_FALSE(dec.overrun());
}

TEST(RangeCoder, RandomStreamsRoundTrip) {
  for (uint32_t seed = 1; seed <= 20; ++seed)
    roundtrip(random_ops(seed, 5000, false));
}

TEST(RangeCoder, SkewedStreamsRoundTrip) {
  for (uint32_t seed = 1; seed <= 20; ++seed)
    roundtrip(random_ops(seed, 20000, true));
}

TEST(RangeCoder, EmptyAndTinyStreams) {
  roundtrip({});
  roundtrip({{1, 1, 0}});
  roundtrip({{2, 0xABCDEF, 24}});
}

TEST(RangeCoder, SkewedBitsCompressWell) {
  std::vector<uint8_t> bytes;
  RangeEncoder enc(&bytes);
  BitModel m;
  for (int i = 0; i < 100000; ++i)
    enc.encode_bit(m, i % 100 == 0);
  enc.finish();
  // Entropy of p=0.01 is 0.081 bits/symbol: 1010 bytes. Allow adaptation overhead.
  EXPECT_LT(bytes.size(), 1400u);
  EXPECT_GT(bytes.size(), 900u);
}

TEST(RangeCoder, TruncatedStreamIsDetected) {
  std::vector<uint8_t> bytes;
  RangeEncoder enc(&bytes);
  for (int i = 0; i < 1000; ++i)
    enc.encode_bypass(uint32_t(i * 2654435761u) >> 8, 24);
  enc.finish();
  RangeDecoder dec(bytes.data(), bytes.size() / 2);
  for (int i = 0; i < 1000; ++i)
    dec.decode_bypass(24);
  EXPECT_TRUE(dec.overrun());
}

TEST(RangeCoder, DominantSymbolNeverReachesFrequencyZero) {
  // A symbol coded over and over climbs towards the 2^16 total; a count kept in 16 bits
  // would wrap (to 0 at 65,512 + 24), after which coding it would never terminate.
  // Where the dominant count lands when the total passes 2^16 depends on the history:
  // warm-ups of 0..59 updates of another symbol cover cases that reach 0 in 16 bits (e.g. 6).
  for (int symbols : {2, 3, 17, 40, 64}) {
    for (int warmup = 0; warmup < 60; ++warmup) {
      FrequencyModel model(symbols);
      for (int i = 0; i < warmup; ++i)
        model.update(0);
      for (int i = 0; i < 20000; ++i) {
        model.update(symbols - 1);
        ASSERT_GT(model.freq(symbols - 1), 0u) << symbols << " symbols, warm-up " << warmup;
      }
      uint32_t total = 0;
      for (int k = 0; k < symbols; ++k) {
        EXPECT_GT(model.freq(k), 0u);
        total += model.freq(k);
      }
      EXPECT_EQ(total, model.total());
    }
    // And a long skewed stream round-trips.
    std::vector<uint8_t> bytes;
    RangeEncoder enc(&bytes);
    FrequencyModel em(symbols), dm(symbols);
    for (int i = 0; i < 6; ++i)
      enc.encode(em, 0);
    for (int i = 0; i < 300000; ++i)
      enc.encode(em, i % 5000 == 0 ? 0 : symbols - 1);
    enc.finish();
    RangeDecoder dec(bytes.data(), bytes.size());
    for (int i = 0; i < 6; ++i)
      ASSERT_EQ(dec.decode(dm), 0);
    for (int i = 0; i < 300000; ++i)
      ASSERT_EQ(dec.decode(dm), i % 5000 == 0 ? 0 : symbols - 1) << i;
    EXPECT_FALSE(dec.overrun());
  }
}

// The static tables store each frequency as its nearest log-scale code; the fast search
// must pick exactly the code the plain search over all 103 codes picks (the files depend
// on it), for every frequency a model can hold.
TEST(StaticTables, LogCodeSearchMatchesThePlainSearchForEveryFrequency) {
  for (uint32_t f = 1; f <= FrequencyModel::kMaxTotal; ++f)
    ASSERT_EQ(log_code(f), log_code_reference(f)) << "frequency " << f;
}

} // namespace
} // namespace pomar
