#include "server/raise_priority.h"

#include <sys/resource.h>

namespace cohaptic {

bool raise_priority(int nice) { return setpriority(PRIO_PROCESS, 0, nice) == 0; }

}  // namespace cohaptic
