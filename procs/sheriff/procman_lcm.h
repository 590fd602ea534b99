#pragma once
// Conversions between procman_protocol.h and libbot2 procman's wire types
// (lcmtypes/procman/, package bot_procman). The only sheriff/deputy code
// that knows LCM types; the mains use it.

#include <bot_procman/discovery_t.hpp>
#include <bot_procman/info2_t.hpp>
#include <bot_procman/orders2_t.hpp>
#include <bot_procman/printf_t.hpp>

#include "procs/sheriff/procman_protocol.h"

namespace vimot::sheriff {

bot_procman::orders2_t ToLcm(const DeputyOrders& orders);
bot_procman::info2_t ToLcm(const DeputyInfo& info);
bot_procman::printf_t ToLcm(const DeputyOutput& output);

DeputyOrders FromLcm(const bot_procman::orders2_t& msg);
DeputyInfo FromLcm(const bot_procman::info2_t& msg);
DeputyOutput FromLcm(const bot_procman::printf_t& msg);

}  // namespace vimot::sheriff
