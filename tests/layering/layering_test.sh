#!/usr/bin/env bash
# The layering of docs/architecture.md, checked on the sources:
#  * nothing under common/ includes procs/ or drivers/ (processes and
#    evaluators call common/, never the other way round);
#  * no LCM under common/ except common/process (the scaffold, the message
#    conversions and the log reader): no <lcm/...> and no generated
#    "vimot/*.hpp" message header anywhere else in common/.
# Usage: layering_test.sh <source dir>
set -u
src=${1:?usage: layering_test.sh <source dir>}
cd "$src" || exit 2
status=0

up=$(grep -rnE '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"](procs|drivers)/' common || true)
if [ -n "$up" ]; then
  echo "common/ must not include procs/ or drivers/:"
  echo "$up"
  status=1
fi

lcm=$(grep -rnE '^[[:space:]]*#[[:space:]]*include[[:space:]]*[<"](lcm/|vimot/[a-z_0-9]+_t\.hpp)' common \
        --exclude-dir=process || true)
if [ -n "$lcm" ]; then
  echo "LCM headers outside common/process:"
  echo "$lcm"
  status=1
fi

[ $status -eq 0 ] && echo "layering ok"
exit $status
