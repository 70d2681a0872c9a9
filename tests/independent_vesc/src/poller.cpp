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
  // Per request: the round trip r = max(r_min, m·e^{σZ}), then the wait for the timer's next tick (P/2 on
  // average) and the event loop (0.5 ms); a stall adds U[0.3, stall_max]; a loss replaces the cycle by the 1 s
  // time-out and costs its row. Mean row interval = (time per request) / (1 − p_loss), solved for the median m.
  const double period = timer_period_s(p.poll_rate_Hz);
  const double s = std::max(p.rtt_sigma_log, 1e-9);
  auto phi = [](double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); };
  auto mean_interval = [&](double m) {
    const double z = std::log(p.rtt_min_s > 0.0 ? p.rtt_min_s / m : 1e-300) / s;
    const double rtt = p.rtt_min_s * phi(z) + m * std::exp(0.5 * s * s) * phi(s - z);
    const double cycle = (1.0 - p.loss_probability) * (rtt + 0.5 * period + 5e-4) +
                         p.loss_probability * (1.0 + 0.5 * period) + p.stall_probability * 0.5 * (0.3 + p.stall_max_s);
    return cycle / (1.0 - p.loss_probability);
  };
  double lo = 1e-4, hi = 10.0;
  for (int k = 0; k < 100; ++k) {
    const double mid = std::sqrt(lo * hi);
    (mean_interval(mid) < 1.0 / p.rate_Hz ? lo : hi) = mid;
  }
  return std::sqrt(lo * hi);
}

std::vector<ReadEvent> poll_schedule(const Poller& p, double duration_s, std::uint64_t seed) {
  std::mt19937_64 rng = stream_rng(seed, Stream::link);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double period = timer_period_s(p.poll_rate_Hz);
  const double median = rtt_median_s(p);
  const double timeout_s = 100 * 10e-3;  // mTimeoutCount ticks of the 10 ms timer

  std::vector<ReadEvent> reads;
  double can_send_at = 0.0;  // the time-out runs out (when a request is outstanding)
  bool outstanding = false;
  std::vector<double> replies;  // arrival times of replies still under way
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
    const double split = 0.3 + 0.4 * unit(rng);       // the request's share of the round trip
    if (u_loss < 0.5 * p.loss_probability) continue;  // the request was lost: no read, no reply
    ReadEvent e;
    e.t_request_s = t;
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
