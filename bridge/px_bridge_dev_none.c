/* The "dds" device back end of a build without Cyclone DDS: refused,
 * saying what is missing. */
#include <stdio.h>

#include "bridge_internal.h"

int px_bridge_dev_create(const struct px_dev_config *dc,
			 const struct px_bridge_dev_config *bc,
			 struct px_dev **out, char *msg, size_t cap)
{
	(void)dc, (void)bc;
	if (out)
		*out = NULL;
	if (msg && cap)
		snprintf(msg, cap, "dds device: this build has no DDS "
				   "(built without Cyclone DDS)");
	return PX_E_UNSUPPORTED;
}

int px_bridge_dev_wrench(struct px_dev *d, struct px_force_cmd *out,
			 int64_t *t_ns)
{
	(void)d, (void)out, (void)t_ns;
	return PX_E_INVAL;
}

int px_bridge_dev_pose_write(struct px_dev *d, const px_vec3 *pos_m,
			     const px_quat *q)
{
	(void)d, (void)pos_m, (void)q;
	return PX_E_INVAL;
}

int px_bridge_dev_counts(struct px_dev *d, struct px_bridge_dev_counts *out)
{
	(void)d, (void)out;
	return PX_E_INVAL;
}

int px_bridge_dev_params(struct px_dev *d, struct px_bridge_params *out)
{
	(void)d, (void)out;
	return PX_E_INVAL;
}

int px_bridge_dev_scene_poses(struct px_dev *d,
			      struct px_bridge_scene_poses *out)
{
	(void)d, (void)out;
	return PX_E_INVAL;
}

int px_bridge_dev_joint_state(struct px_dev *d,
			      struct px_bridge_joint_state *out)
{
	(void)d, (void)out;
	return PX_E_INVAL;
}

int px_bridge_dev_joint_command(struct px_dev *d, const double *position_rad,
				const double *velocity_rad_per_s)
{
	(void)d, (void)position_rad, (void)velocity_rad_per_s;
	return PX_E_INVAL;
}

int px_bridge_dev_joint_hold(struct px_dev *d)
{
	(void)d;
	return PX_E_INVAL;
}
