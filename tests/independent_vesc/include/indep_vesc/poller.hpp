#pragma once
// When VESC Tool reads the VESC and when it writes the row (README "Reads"), from vedderb/vesc_tool:
//  - mainwindow.cpp: the realtime-data timer fires every int(1000/poll_rate_rt_data) ms (default 50 Hz) and
//    calls Commands::getValues() (and getValuesSetup());
//  - commands.cpp, getValues(): nothing is sent while a request is outstanding (mTimeoutValues > 0); sending sets
//    it to 100, a reply clears it, the 10 ms timerSlot() counts it down: a lost request or reply therefore
//    silences the log for about a second;
//  - vescinterface.cpp: the row is written when the reply arrives, stamped with the host's clock then.
// The firmware reads and resets its averages when the request arrives (commands.c), so a row's window runs
// from the previous request's arrival (logged or not) to its own.
#include <cstdint>
#include <vector>

#include "indep_vesc/case.hpp"

namespace indep::vesc {

struct ReadEvent {
  double t_request_s = 0.0;      // VESC Tool sends COMM_GET_VALUES
  double t_read_s = 0.0;         // the request reaches the VESC: averages read and reset
  bool logged = true;            // false: the reply was lost
  double t_reply_s = 0.0;        // the reply reaches VESC Tool: the row's timestamp
  double t_setup_reply_s = 0.0;  // COMM_GET_VALUES_SETUP's reply, sent in the same timer tick
};

/// Every read in [0, duration_s], in the order of t_read_s.
std::vector<ReadEvent> poll_schedule(const Poller& p, double duration_s, std::uint64_t seed);

/// The round trip's median [s] that makes the mean row interval 1/rate_Hz at the poll timer's period.
double rtt_median_s(const Poller& p);

}  // namespace indep::vesc
