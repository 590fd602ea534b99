#pragma once
// Conversions between procman_protocol.h and libbot2 procman's wire types
// (lcmtypes/procman/, package bot_procman). The only sheriff/deputy code
// that knows LCM types; the mains use it.

#include <bot_procman/discovery_t.hpp>
#include <bot_procman/info2_t.hpp>
#include <bot_procman/orders2_t.hpp>
#include <bot_procman/printf_t.hpp>

#include <exception>

#include "common/process/lcm_layout.h"
#include "procs/sheriff/procman_protocol.h"

namespace vimot::sheriff {

/// Wire layouts of procman's types, member by member as libbot2's
/// bot2-procman/lcmtypes define them (written by hand, not from our .lcm
/// files): lcm_fingerprint() of each must equal the generated getHash(), and
/// they bound every length before a decoder allocates.
struct ProcmanLayouts {
  const LcmStruct& command2;
  const LcmStruct& sheriff_cmd2;
  const LcmStruct& deputy_cmd2;
  const LcmStruct& orders2;
  const LcmStruct& info2;
  const LcmStruct& printf_msg;
  const LcmStruct& discovery;
};
const ProcmanLayouts& procman_layouts();

template <typename Msg>
const LcmStruct& ProcmanLayout();
template <>
inline const LcmStruct& ProcmanLayout<bot_procman::orders2_t>() { return procman_layouts().orders2; }
template <>
inline const LcmStruct& ProcmanLayout<bot_procman::info2_t>() { return procman_layouts().info2; }
template <>
inline const LcmStruct& ProcmanLayout<bot_procman::printf_t>() { return procman_layouts().printf_msg; }
template <>
inline const LcmStruct& ProcmanLayout<bot_procman::discovery_t>() {
  return procman_layouts().discovery;
}

/// Decodes bytes from the network as Msg: false, without allocating, when a
/// length does not fit in `size`, and false when the generated decoder
/// rejects them (wrong fingerprint) or they hold more than one message.
template <typename Msg>
bool DecodeProcman(const void* data, int size, Msg* msg) {
  if (!lcm_lengths_fit(ProcmanLayout<Msg>(), data, size)) return false;
  try {
    return msg->decode(data, 0, size) == size;
  } catch (const std::exception&) {
    return false;  // lcm-gen 1.3 decoders throw on some corrupt lengths
  }
}

bot_procman::orders2_t ToLcm(const DeputyOrders& orders);
bot_procman::info2_t ToLcm(const DeputyInfo& info);
bot_procman::printf_t ToLcm(const DeputyOutput& output);

DeputyOrders FromLcm(const bot_procman::orders2_t& msg);
DeputyInfo FromLcm(const bot_procman::info2_t& msg);
DeputyOutput FromLcm(const bot_procman::printf_t& msg);

}  // namespace vimot::sheriff
