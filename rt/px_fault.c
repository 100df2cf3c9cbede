#include "px_fault.h"

static const char *const names[PX_FAULT__COUNT] = {
	"none",          "input_stale", "compute_budget", "output_nonfinite",
	"overrun",       "callback",    "trip",           "estop",
};

const char *px_fault_cause_name(int cause)
{
	if (cause < 0 || cause >= PX_FAULT__COUNT)
		return "unknown";
	return names[cause];
}
