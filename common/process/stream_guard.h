#pragma once
// Timing guard of one input stream (IMU, FEATURES) of a node:
// bounds how far one message may jump from the stream's clock, tells a
// single bad timestamp (rejected, the clock kept) from a source whose clock
// really moved (several consistent jumps: a source reset), and counts input
// lost on the way (utime gaps against the expected period; a rejected
// message fills one slot of the gap, so each missing sample is counted
// once, as rejected or as lost). No LCM.
// Thresholds and what the nodes do: docs/robustness.md.

#include <cstdint>
#include <string>

namespace vimot {

struct StreamGuardOptions {
  double expected_period_s{0.0};     // nominal spacing; 0: unknown, no loss counting
  double max_forward_jump_s{1.0};    // a step further ahead is suspect
  double max_backward_jump_s{1.0};   // a step further back is suspect (smaller: left to the consumer)
  int reset_after{3};                // consecutive consistent suspect messages that make a source reset
  /// A source reset forward by at most this is an outage (e.g. a process
  /// that fell behind and whose input queue overflowed): the messages it
  /// skipped count as lost. Further: a new clock, nothing counted.
  double max_outage_s{60.0};

  /// Throws std::invalid_argument naming the bad option.
  void validate() const;
};

enum class StreamVerdict {
  kAccept,       // pass on (a duplicate or slightly old message is the consumer's to drop)
  kRejectJump,   // drop: too far from the stream's clock
  kSourceReset,  // the source's clock moved: restart from this message
};

struct StreamCheck {
  StreamVerdict verdict{StreamVerdict::kAccept};
  int64_t lost{0};       // messages missing before this one (kAccept, or kSourceReset after an outage)
  std::string message;   // why, for the log (empty when accepted without loss)
};

class StreamGuard {
 public:
  StreamGuard(std::string name, const StreamGuardOptions& options);

  StreamCheck check(int64_t utime);
  /// Forgets the clock: the next message is taken as the first (a step
  /// forward from the old clock up to max_outage_s still counts as lost).
  void reset();

  const std::string& name() const { return name_; }
  /// False until the first message (or after reset()).
  bool started() const { return has_last_; }
  int64_t lost() const { return lost_; }
  int64_t rejected() const { return rejected_; }
  int64_t source_resets() const { return source_resets_; }

 private:
  std::string name_;
  StreamGuardOptions options_;
  /// Counts the messages a forward step of `step_s` skipped (less those
  /// rejected in it) into out->lost when it is an outage; returns the count.
  int64_t count_outage(double step_s, StreamCheck* out);

  bool has_last_{false};
  bool has_old_{false};  // last_ is a clock from before reset()
  int64_t last_{0};
  int suspects_{0};
  int64_t last_suspect_{0};
  int64_t rejected_since_accept_{0};
  int64_t lost_{0};
  int64_t rejected_{0};
  int64_t source_resets_{0};
};

}  // namespace vimot
