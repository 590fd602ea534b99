#pragma once
// What a script needs from whoever runs the commands: the local
// ProcessRunner, or RemoteCommands, which has deputies run them over
// procman's LCM protocol (vimot-sheriff --lcm).

#include <string>

namespace vimot::sheriff {

struct CommandState;

class CommandControl {
 public:
  virtual ~CommandControl() = default;
  /// Throw std::invalid_argument for an unknown name.
  virtual void Start(const std::string& name) = 0;
  virtual void Stop(const std::string& name) = 0;
  virtual void Restart(const std::string& name) = 0;
  /// False for commands this controller does not run (another host's).
  virtual bool IsLocal(const std::string& name) const = 0;
  virtual const CommandState& state(const std::string& name) const = 0;
};

}  // namespace vimot::sheriff
