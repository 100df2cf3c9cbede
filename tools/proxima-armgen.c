/*
 * proxima-armgen - write the example 6-joint arm: a URDF file and one
 * binary STL mesh per link (closed prisms with rounded-off ends), the
 * files config/examples/robots/arm6/ holds.
 *
 *   proxima-armgen DIR     writes DIR/arm6.urdf and DIR/meshes/NAME.stl
 *
 * The output depends on nothing but this file (coordinates rounded to
 * float, as binary STL stores them), so a test regenerates the files
 * and compares them byte for byte with the ones shipped.
 *
 * The arm, z up, all revolute: shoulder_pan about z at the top of the
 * base column, shoulder_lift and elbow about y, the upper arm and the
 * forearm along x at q = 0, then three wrist joints (y, z, x) and a
 * fixed tool frame. Meshes are modelled along z and turned onto x by
 * their collision origins; the shoulder and base meshes are found as
 * package://arm6/meshes/..., the others by paths relative to the URDF.
 */
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>

#define SIDES 12

/* One link mesh: a prism of SIDES sides, radius r, from z = 0 to z = len,
 * each end closed by a cone of height r/2 (so the ends are not flat). */
struct part {
	const char *name;
	double r, len;
};

static const struct part parts[] = {
	{"base", 0.08, 0.10},
	{"shoulder", 0.065, 0.12},
	{"upper_arm", 0.055, 0.40},
	{"forearm", 0.045, 0.35},
	{"wrist1", 0.04, 0.09},
	{"wrist2", 0.04, 0.09},
	{"wrist3", 0.035, 0.06},
};
#define N_PARTS (sizeof(parts) / sizeof(parts[0]))

static void put_f32(FILE *f, double v)
{
	float x = (float)v;
	unsigned char b[4];
	uint32_t u;
	memcpy(&u, &x, 4);
	b[0] = (unsigned char)(u & 0xff);
	b[1] = (unsigned char)((u >> 8) & 0xff);
	b[2] = (unsigned char)((u >> 16) & 0xff);
	b[3] = (unsigned char)((u >> 24) & 0xff);
	fwrite(b, 1, 4, f);
}

static void put_tri(FILE *f, const double *a, const double *b, const double *c)
{
	static const unsigned char attr[2] = {0, 0};
	int k;
	for (k = 0; k < 3; k++)
		put_f32(f, 0.0); /* normal: readers take the winding */
	for (k = 0; k < 3; k++)
		put_f32(f, a[k]);
	for (k = 0; k < 3; k++)
		put_f32(f, b[k]);
	for (k = 0; k < 3; k++)
		put_f32(f, c[k]);
	fwrite(attr, 1, 2, f);
}

static int write_part(const char *dir, const struct part *p)
{
	char path[1200];
	unsigned char head[80];
	double ring[SIDES][2], tip0[3] = {0, 0, 0}, tip1[3];
	uint32_t n = 4 * SIDES;
	FILE *f;
	int i;
	snprintf(path, sizeof(path), "%s/meshes/%s.stl", dir, p->name);
	f = fopen(path, "wb");
	if (!f) {
		fprintf(stderr, "proxima-armgen: %s: %s\n", path, strerror(errno));
		return 1;
	}
	memset(head, 0, sizeof(head));
	snprintf((char *)head, sizeof(head), "proxima arm6 %s", p->name);
	fwrite(head, 1, sizeof(head), f);
	for (i = 0; i < 4; i++)
		fputc((int)((n >> (8 * i)) & 0xff), f);
	for (i = 0; i < SIDES; i++) {
		double t = 2 * M_PI * (i + 0.5) / SIDES;
		ring[i][0] = p->r * cos(t);
		ring[i][1] = p->r * sin(t);
	}
	tip0[2] = -0.5 * p->r;
	tip1[0] = tip1[1] = 0;
	tip1[2] = p->len + 0.5 * p->r;
	for (i = 0; i < SIDES; i++) {
		int j = (i + 1) % SIDES;
		double a0[3] = {ring[i][0], ring[i][1], 0}, b0[3] = {ring[j][0], ring[j][1], 0};
		double a1[3] = {ring[i][0], ring[i][1], p->len};
		double b1[3] = {ring[j][0], ring[j][1], p->len};
		/* side (outward), then the two end cones */
		put_tri(f, a0, b0, b1);
		put_tri(f, a0, b1, a1);
		put_tri(f, tip0, b0, a0);
		put_tri(f, tip1, a1, b1);
	}
	if (fclose(f) != 0) {
		fprintf(stderr, "proxima-armgen: %s: %s\n", path, strerror(errno));
		return 1;
	}
	return 0;
}

/* The URDF: each link's mesh at its origin in the link frame, and the
 * joints between them. */
static const char *urdf_text =
	"<?xml version=\"1.0\"?>\n"
	"<!-- Written by proxima-armgen: the example arm of\n"
	"     config/examples/can_avoid_urdf.yaml. -->\n"
	"<robot name=\"arm6\">\n"
	"  <link name=\"base_link\">\n"
	"    <collision><origin xyz=\"0 0 0.04\"/>"
	"<geometry><mesh filename=\"package://arm6/meshes/base.stl\"/></geometry></collision>\n"
	"  </link>\n"
	"  <link name=\"shoulder_link\">\n"
	"    <collision><origin xyz=\"0 0 0.0325\"/>"
	"<geometry><mesh filename=\"package://arm6/meshes/shoulder.stl\"/></geometry></collision>\n"
	"  </link>\n"
	"  <link name=\"upper_arm_link\">\n"
	"    <collision><origin rpy=\"0 1.5707963267948966 0\"/>"
	"<geometry><mesh filename=\"meshes/upper_arm.stl\"/></geometry></collision>\n"
	"  </link>\n"
	"  <link name=\"forearm_link\">\n"
	"    <collision><origin rpy=\"0 1.5707963267948966 0\"/>"
	"<geometry><mesh filename=\"meshes/forearm.stl\"/></geometry></collision>\n"
	"  </link>\n"
	"  <link name=\"wrist1_link\">\n"
	"    <collision><origin rpy=\"0 1.5707963267948966 0\"/>"
	"<geometry><mesh filename=\"meshes/wrist1.stl\"/></geometry></collision>\n"
	"  </link>\n"
	"  <link name=\"wrist2_link\">\n"
	"    <collision><origin rpy=\"0 1.5707963267948966 0\"/>"
	"<geometry><mesh filename=\"meshes/wrist2.stl\"/></geometry></collision>\n"
	"  </link>\n"
	"  <link name=\"wrist3_link\">\n"
	"    <collision><origin rpy=\"0 1.5707963267948966 0\"/>"
	"<geometry><mesh filename=\"meshes/wrist3.stl\"/></geometry></collision>\n"
	"  </link>\n"
	"  <link name=\"tool0\"/>\n"
	"  <joint name=\"shoulder_pan\" type=\"revolute\">\n"
	"    <parent link=\"base_link\"/><child link=\"shoulder_link\"/>\n"
	"    <origin xyz=\"0 0 0.18\"/><axis xyz=\"0 0 1\"/>\n"
	"    <limit lower=\"-3.14159\" upper=\"3.14159\" velocity=\"2.0\" effort=\"150\"/>\n"
	"  </joint>\n"
	"  <joint name=\"shoulder_lift\" type=\"revolute\">\n"
	"    <parent link=\"shoulder_link\"/><child link=\"upper_arm_link\"/>\n"
	"    <origin xyz=\"0 0 0.2\"/><axis xyz=\"0 1 0\"/>\n"
	"    <limit lower=\"-3.14159\" upper=\"3.14159\" velocity=\"2.0\" effort=\"150\"/>\n"
	"  </joint>\n"
	"  <joint name=\"elbow\" type=\"revolute\">\n"
	"    <parent link=\"upper_arm_link\"/><child link=\"forearm_link\"/>\n"
	"    <origin xyz=\"0.45 0 0\"/><axis xyz=\"0 1 0\"/>\n"
	"    <limit lower=\"-2.8\" upper=\"2.8\" velocity=\"2.5\" effort=\"80\"/>\n"
	"  </joint>\n"
	"  <joint name=\"wrist1\" type=\"revolute\">\n"
	"    <parent link=\"forearm_link\"/><child link=\"wrist1_link\"/>\n"
	"    <origin xyz=\"0.39 0 0\"/><axis xyz=\"0 1 0\"/>\n"
	"    <limit lower=\"-3.14159\" upper=\"3.14159\" velocity=\"3.0\" effort=\"30\"/>\n"
	"  </joint>\n"
	"  <joint name=\"wrist2\" type=\"revolute\">\n"
	"    <parent link=\"wrist1_link\"/><child link=\"wrist2_link\"/>\n"
	"    <origin xyz=\"0.11 0 0\"/><axis xyz=\"0 0 1\"/>\n"
	"    <limit lower=\"-3.14159\" upper=\"3.14159\" velocity=\"3.0\" effort=\"30\"/>\n"
	"  </joint>\n"
	"  <joint name=\"wrist3\" type=\"revolute\">\n"
	"    <parent link=\"wrist2_link\"/><child link=\"wrist3_link\"/>\n"
	"    <origin xyz=\"0.11 0 0\"/><axis xyz=\"1 0 0\"/>\n"
	"    <limit lower=\"-3.14159\" upper=\"3.14159\" velocity=\"3.0\" effort=\"30\"/>\n"
	"  </joint>\n"
	"  <joint name=\"tool_flange\" type=\"fixed\">\n"
	"    <parent link=\"wrist3_link\"/><child link=\"tool0\"/>\n"
	"    <origin xyz=\"0.08 0 0\"/>\n"
	"  </joint>\n"
	"</robot>\n";

int main(int argc, char **argv)
{
	char path[1200];
	FILE *f;
	size_t i;
	if (argc != 2 || argv[1][0] == '-') {
		fprintf(stderr, "usage: proxima-armgen DIR\n"
				"writes DIR/arm6.urdf and DIR/meshes/*.stl\n");
		return 2;
	}
	snprintf(path, sizeof(path), "%s/meshes", argv[1]);
	if (mkdir(argv[1], 0755) != 0 && errno != EEXIST) {
		fprintf(stderr, "proxima-armgen: %s: %s\n", argv[1], strerror(errno));
		return 1;
	}
	if (mkdir(path, 0755) != 0 && errno != EEXIST) {
		fprintf(stderr, "proxima-armgen: %s: %s\n", path, strerror(errno));
		return 1;
	}
	for (i = 0; i < N_PARTS; i++)
		if (write_part(argv[1], &parts[i]))
			return 1;
	snprintf(path, sizeof(path), "%s/arm6.urdf", argv[1]);
	f = fopen(path, "w");
	if (!f || fputs(urdf_text, f) < 0 || fclose(f) != 0) {
		fprintf(stderr, "proxima-armgen: %s: %s\n", path, strerror(errno));
		return 1;
	}
	return 0;
}
