/* The bridge of a build without Cyclone DDS: the config side works (a
 * config with a bridge section still checks), joining a domain says
 * what is missing. */
#include <stdio.h>
#include <string.h>

#include "bridge_internal.h"

int px_bridge_create(const struct px_bridge_config *c, struct px_bridge **out,
		     char *msg, size_t cap)
{
	(void)c;
	if (out)
		*out = NULL;
	if (msg && cap)
		snprintf(msg, cap, "bridge: this build has no DDS bridge "
				   "(built without Cyclone DDS)");
	return PX_E_UNSUPPORTED;
}

const void *px_bridge_topic_descriptor(enum px_bridge_topic t)
{
	(void)t;
	return NULL;
}

int px_bridge_offer(struct px_bridge *b, const struct px_bridge_sample *s)
{
	(void)b, (void)s;
	return PX_E_UNSUPPORTED;
}

int px_bridge_offer_status(struct px_bridge *b,
			   const struct px_bridge_status *s)
{
	(void)b, (void)s;
	return PX_E_UNSUPPORTED;
}

int px_bridge_publish_joint_state(struct px_bridge *b, int64_t stamp_ns,
				  size_t n, const char *const *names,
				  const double *position_rad,
				  const double *velocity_rad_per_s,
				  const double *effort_n_m)
{
	(void)b, (void)stamp_ns, (void)n, (void)names, (void)position_rad;
	(void)velocity_rad_per_s, (void)effort_n_m;
	return PX_E_UNSUPPORTED;
}

int px_bridge_publish_cloud(struct px_bridge *b, int64_t stamp_ns,
			    const float *xyz_m, size_t n)
{
	(void)b, (void)stamp_ns, (void)xyz_m, (void)n;
	return PX_E_UNSUPPORTED;
}

int px_bridge_wait_readers(struct px_bridge *b, int min_readers,
			   int64_t timeout_ns)
{
	(void)b, (void)min_readers, (void)timeout_ns;
	return PX_E_UNSUPPORTED;
}

void px_bridge_counts(struct px_bridge *b, struct px_bridge_counts *out)
{
	(void)b;
	if (out)
		memset(out, 0, sizeof(*out));
}

void px_bridge_free(struct px_bridge *b)
{
	(void)b;
}
