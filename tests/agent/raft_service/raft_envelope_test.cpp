// RaftMessage <-> raft::Transport mapping and the receiver's addressing rule, without DDS.
#include "swarmbox/raft_service/raft_envelope.hpp"

#include <gtest/gtest.h>

#include "swarmbox/raft/message_codec.hpp"

namespace swarmbox::raft_service {
namespace {

raft::Bytes EncodedHeartbeat(std::uint64_t term) {
  raft::Message m;
  m.type = raft::MessageType::kHeartbeat;
  m.from = 1;
  m.to = 3;
  m.term = term;
  m.commit = 7;
  return raft::EncodeMessage(m, raft::ClusterTag({"a", "b", "c"}));
}

TEST(RaftEnvelope, WrapFillsEveryFieldAndKeepsPayloadBytes) {
  const raft::Bytes bytes = EncodedHeartbeat(9);
  const bus::RaftMessage m = WrapRaftPayload("scout_1", "lifter", bytes);
  EXPECT_EQ(m.from, "scout_1");
  EXPECT_EQ(m.to, "lifter");
  EXPECT_EQ(m.term, 9u);
  EXPECT_EQ(m.payload, bytes);
}

TEST(RaftEnvelope, PeekTermReadsLargeVarintTermsOfTheCodec) {
  for (std::uint64_t term : {0ull, 1ull, 127ull, 128ull, 300ull, 1ull << 40}) {
    EXPECT_EQ(PeekRaftTerm(EncodedHeartbeat(term)), term) << term;
  }
}

TEST(RaftEnvelope, PeekTermOfMalformedBytesIsZero) {
  EXPECT_EQ(PeekRaftTerm({}), 0u);
  raft::Bytes b = EncodedHeartbeat(5);
  raft::Bytes wrong_version = b;
  wrong_version[0] = 99;
  EXPECT_EQ(PeekRaftTerm(wrong_version), 0u);
  raft::Bytes truncated(b.begin(), b.begin() + 7);  // header + from only
  EXPECT_EQ(PeekRaftTerm(truncated), 0u);
  raft::Bytes endless(b.begin(), b.begin() + 6);
  endless.insert(endless.end(), 12, 0xFF);  // a varint that never ends
  EXPECT_EQ(PeekRaftTerm(endless), 0u);
}

TEST(RaftEnvelope, WrapOfNonCodecBytesStillCarriesThemWithTermZero) {
  const raft::Bytes junk = {1, 2, 3};
  const bus::RaftMessage m = WrapRaftPayload("a", "b", junk);
  EXPECT_EQ(m.term, 0u);
  EXPECT_EQ(m.payload, junk);
}

TEST(RaftEnvelope, ReceiverDeliversOnlyPayloadsAddressedToItByOthers) {
  const raft::Bytes bytes = EncodedHeartbeat(2);
  EXPECT_EQ(ClassifyRaftMessage(WrapRaftPayload("scout_1", "lifter", bytes), "lifter"),
            RaftDelivery::kDeliver);
  EXPECT_EQ(ClassifyRaftMessage(WrapRaftPayload("scout_1", "scout_2", bytes), "lifter"),
            RaftDelivery::kNotForUs);
  EXPECT_EQ(ClassifyRaftMessage(WrapRaftPayload("lifter", "scout_2", bytes), "lifter"),
            RaftDelivery::kOwn);
  // Own messages are dropped even if (wrongly) addressed to self.
  EXPECT_EQ(ClassifyRaftMessage(WrapRaftPayload("lifter", "lifter", bytes), "lifter"),
            RaftDelivery::kOwn);
  EXPECT_EQ(ClassifyRaftMessage(WrapRaftPayload("scout_1", "lifter", {}), "lifter"),
            RaftDelivery::kEmpty);
  // Names compare exactly: no prefix or case folding.
  EXPECT_EQ(ClassifyRaftMessage(WrapRaftPayload("scout_1", "lifter_2", bytes), "lifter"),
            RaftDelivery::kNotForUs);
  EXPECT_EQ(ClassifyRaftMessage(WrapRaftPayload("scout_1", "Lifter", bytes), "lifter"),
            RaftDelivery::kNotForUs);
}

TEST(RaftEnvelope, DeliveryNamesAreStable) {
  EXPECT_EQ(RaftDeliveryName(RaftDelivery::kDeliver), "deliver");
  EXPECT_EQ(RaftDeliveryName(RaftDelivery::kNotForUs), "not_for_us");
  EXPECT_EQ(RaftDeliveryName(RaftDelivery::kOwn), "own");
  EXPECT_EQ(RaftDeliveryName(RaftDelivery::kEmpty), "empty");
}

}  // namespace
}  // namespace swarmbox::raft_service
