#include "indep_vesc/poller.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include "indep_vesc/random_streams.hpp"

namespace indep::vesc {

namespace {

/// QTimer's interval for a rate: int(1000/rate) milliseconds.
double timer_period_s(double rate_Hz) { return std::floor(1000.0 / rate_Hz) * 1e-3; }

}  // namespace

double rtt_median_s(const Poller& p) {
  // A reply that comes back after a round trip r is followed by the next request at the next timer tick, on
  // average half a period later: mean interval ≈ E[r] + P/2, and E[r] = median·e^{σ²/2}.
  const double period = timer_period_s(p.poll_rate_Hz);
  const double mean_rtt = std::max(1.0 / p.rate_Hz - 0.5 * period, p.rtt_min_s);
  return mean_rtt / std::exp(0.5 * p.rtt_sigma_log * p.rtt_sigma_log);
}

std::vector<ReadEvent> poll_schedule(const Poller& p, double duration_s, std::uint64_t seed) {
  std::mt19937_64 rng = stream_rng(seed, Stream::link);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double period = timer_period_s(p.poll_rate_Hz);
  const double median = rtt_median_s(p);
  const double timeout_s = 100 * 10e-3;  // mTimeoutCount ticks of the 10 ms timer

  std::vector<ReadEvent> reads;
  double can_send_at = 0.0;      // the time-out runs out (when a request is outstanding)
  bool outstanding = false;
  std::vector<double> replies;   // arrival times of replies still under way
  for (double tick = period * unit(rng); tick <= duration_s; tick += period) {
    const double t = tick + 1e-3 * unit(rng);  // the event loop's latency
    // Replies that arrived by now cleared the outstanding request.
    for (auto it = replies.begin(); it != replies.end();) {
      if (*it <= t) {
        outstanding = false;
        it = replies.erase(it);
      } else {
        ++it;
      }
    }
    if (outstanding && t < can_send_at) continue;
    outstanding = true;
    // The 10 ms timer's phase: the count reaches zero between 0.99 and 1.0 s after the request.
    can_send_at = t + timeout_s - 10e-3 * unit(rng);
    double rtt = std::max(p.rtt_min_s, median * std::exp(p.rtt_sigma_log * normal(rng)));
    if (unit(rng) < p.stall_probability) rtt += 0.3 + (p.stall_max_s - 0.3) * unit(rng);
    const double u_loss = unit(rng);
    const double split = 0.3 + 0.4 * unit(rng);  // the request's share of the round trip
    if (u_loss < 0.5 * p.loss_probability) continue;  // the request was lost: no read, no reply
    ReadEvent e;
    e.t_read_s = t + split * rtt;
    e.t_reply_s = t + rtt;
    e.t_setup_reply_s = e.t_reply_s + p.setup_reply_delay_s;
    e.logged = u_loss >= p.loss_probability;  // else the reply was lost
    if (e.t_read_s > duration_s) break;
    if (e.logged) replies.push_back(e.t_reply_s);
    reads.push_back(e);
  }
  std::sort(reads.begin(), reads.end(), [](const ReadEvent& a, const ReadEvent& b) { return a.t_read_s < b.t_read_s; });
  return reads;
}

}  // namespace indep::vesc
