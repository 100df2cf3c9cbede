/* PX_TEST_NEEDS: libxml2 (tests/run.sh skips it in builds without libxml2) */
/*
 * URDF robots (robot/px_urdf.h): a 6-joint arm with boxes, cylinders,
 * spheres, a scaled and a mirrored STL mesh and a fixed tool flange,
 * forward kinematics of every collision shape against an independent
 * computation (4x4 matrices from xyz/rpy and Rodrigues' formula), limits,
 * mesh paths (package://, relative), and every kind of bad file refused
 * with its file, line and element.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "px_alloc_count.h"
#include "px_cloud.h"
#include "px_prim.h"
#include "px_features.h"
#include "px_test.h"
#include "px_urdf.h"

static char dir[256];

static void setup_dir(void)
{
	if (dir[0])
		return;
	snprintf(dir, sizeof(dir), "/tmp/px-urdf-XXXXXX");
	PX_CHECK(mkdtemp(dir) != NULL);
}

static void write_file(const char *path, const char *text)
{
	FILE *f = fopen(path, "w");
	PX_CHECK(f != NULL);
	fputs(text, f);
	fclose(f);
}

/* A unit cube [0,1]^3 as ASCII STL (12 triangles, outward). */
static void write_cube_stl(const char *path)
{
	static const int q[6][4][3] = {
		{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}},
		{{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},
		{{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},
		{{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}},
		{{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}},
		{{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}};
	FILE *f = fopen(path, "w");
	int i, t;
	PX_CHECK(f != NULL);
	fprintf(f, "solid cube\n");
	for (i = 0; i < 6; i++)
		for (t = 0; t < 2; t++) {
			const int *a = q[i][0], *b = q[i][t + 1], *c = q[i][t + 2];
			fprintf(f, " facet normal 0 0 0\n  outer loop\n");
			fprintf(f, "   vertex %d %d %d\n   vertex %d %d %d\n   vertex %d %d %d\n",
				a[0], a[1], a[2], b[0], b[1], b[2], c[0], c[1], c[2]);
			fprintf(f, "  endloop\n endfacet\n");
		}
	fprintf(f, "endsolid cube\n");
	fclose(f);
}

/* The arm: base -> 6 revolute/prismatic joints -> flange (fixed) ->
 * tool (fixed), each link with a collision shape; a camera hangs off
 * link2 by a fixed joint. Origins with rotations everywhere. */
static const char *arm_urdf =
	"<?xml version='1.0'?>\n"
	"<robot name='arm6'>\n"
	"  <material name='grey'><color rgba='0.5 0.5 0.5 1'/></material>\n"
	"  <link name='base'>\n"
	"    <visual><geometry><box size='1 1 1'/></geometry></visual>\n"
	"    <collision><origin xyz='0 0 0.05'/><geometry><cylinder radius='0.1' length='0.1'/></geometry></collision>\n"
	"  </link>\n"
	"  <link name='link1'><collision><origin xyz='0 0 0.1' rpy='0.1 0 0.2'/>"
	"<geometry><box size='0.08 0.1 0.2'/></geometry></collision></link>\n"
	"  <link name='link2'><collision><origin xyz='0.15 0 0' rpy='0 1.5707963267948966 0'/>"
	"<geometry><cylinder radius='0.04' length='0.3'/></geometry></collision>\n"
	"    <collision><origin xyz='0.3 0 0'/><geometry><sphere radius='0.05'/></geometry></collision></link>\n"
	"  <link name='link3'><collision><origin xyz='0.01 -0.02 0.03' rpy='0.3 -0.2 0.1'/>"
	"<geometry><mesh filename='package://armpkg/meshes/cube.stl' scale='0.1 0.05 0.2'/></geometry></collision></link>\n"
	"  <link name='link4'><collision><origin xyz='0 0 0.1'/>"
	"<geometry><mesh filename='meshes/cube.stl' scale='-0.05 0.05 0.1'/></geometry></collision></link>\n"
	"  <link name='link5'><collision><geometry><sphere radius='0.03'/></geometry></collision></link>\n"
	"  <link name='link6'><collision><origin xyz='0 0 0.02'/><geometry><box size='0.03 0.03 0.04'/></geometry></collision></link>\n"
	"  <link name='flange'/>\n"
	"  <link name='tool'><collision><origin xyz='0 0 0.05'/><geometry><cylinder radius='0.01' length='0.1'/></geometry></collision></link>\n"
	"  <link name='camera'><collision><geometry><box size='0.02 0.05 0.02'/></geometry></collision></link>\n"
	"  <joint name='j1' type='revolute'><parent link='base'/><child link='link1'/>"
	"<origin xyz='0 0 0.1'/><axis xyz='0 0 1'/><limit lower='-3' upper='3' velocity='2' effort='50'/></joint>\n"
	"  <joint name='j2' type='revolute'><parent link='link1'/><child link='link2'/>"
	"<origin xyz='0 0 0.2' rpy='-1.5707963267948966 0 0'/><axis xyz='0 0 1'/><limit lower='-2' upper='2' velocity='2' effort='50'/></joint>\n"
	"  <joint name='cam_mount' type='fixed'><parent link='link2'/><child link='camera'/>"
	"<origin xyz='0.1 0.05 0' rpy='0 0 0.5'/></joint>\n"
	"  <joint name='j3' type='continuous'><parent link='link2'/><child link='link3'/>"
	"<origin xyz='0.3 0 0' rpy='0.2 0.1 -0.3'/><axis xyz='0 1 1'/></joint>\n"
	"  <joint name='j4' type='prismatic'><parent link='link3'/><child link='link4'/>"
	"<origin xyz='0 0 0.1'/><axis xyz='1 0 0'/><limit lower='0' upper='0.2' velocity='0.5' effort='100'/></joint>\n"
	"  <joint name='j5' type='revolute'><parent link='link4'/><child link='link5'/>"
	"<origin xyz='0 0 0.2' rpy='0 0.4 0'/><axis xyz='0 1 0'/><limit lower='-2' upper='2' velocity='3'/></joint>\n"
	"  <joint name='j6' type='revolute'><parent link='link5'/><child link='link6'/>"
	"<origin xyz='0 0 0.05'/><axis xyz='0 0 1'/><limit lower='-6' upper='6' velocity='4'/></joint>\n"
	"  <joint name='j_flange' type='fixed'><parent link='link6'/><child link='flange'/>"
	"<origin xyz='0 0 0.04' rpy='0 0 0.7'/></joint>\n"
	"  <joint name='j_tool' type='fixed'><parent link='flange'/><child link='tool'/>"
	"<origin xyz='0.01 0 0.01'/></joint>\n"
	"  <transmission name='t1'><type>x</type></transmission>\n"
	"</robot>\n";

static char arm_path[300], pkg_path[300];

static void write_arm(void)
{
	char p[400];
	setup_dir();
	snprintf(p, sizeof(p), "%s/pkgs/armpkg/meshes", dir);
	mkdir(dir, 0755);
	snprintf(pkg_path, sizeof(pkg_path), "%s/pkgs", dir);
	mkdir(pkg_path, 0755);
	snprintf(p, sizeof(p), "%s/pkgs/armpkg", dir);
	mkdir(p, 0755);
	snprintf(p, sizeof(p), "%s/pkgs/armpkg/meshes", dir);
	mkdir(p, 0755);
	snprintf(p, sizeof(p), "%s/pkgs/armpkg/meshes/cube.stl", dir);
	write_cube_stl(p);
	snprintf(p, sizeof(p), "%s/meshes", dir);
	mkdir(p, 0755);
	snprintf(p, sizeof(p), "%s/meshes/cube.stl", dir);
	write_cube_stl(p);
	snprintf(arm_path, sizeof(arm_path), "%s/arm.urdf", dir);
	write_file(arm_path, arm_urdf);
}

static struct px_urdf *load_arm(void)
{
	const char *paths[1];
	struct px_urdf_opts o;
	struct px_urdf_error e;
	struct px_urdf *u = NULL;
	int rc;
	write_arm();
	paths[0] = pkg_path;
	memset(&o, 0, sizeof(o));
	o.package_paths = paths;
	o.n_package_paths = 1;
	rc = px_urdf_load(arm_path, &o, &u, &e);
	PX_CHECK_MSG(rc == PX_OK, "%s", e.msg);
	return u;
}

/* ---- independent kinematics: 4x4 matrices ------------------------------- */

typedef struct {
	double m[4][4];
} mat4;

static mat4 m_id(void)
{
	mat4 r;
	memset(&r, 0, sizeof(r));
	r.m[0][0] = r.m[1][1] = r.m[2][2] = r.m[3][3] = 1.0;
	return r;
}

static mat4 m_mul(mat4 a, mat4 b)
{
	mat4 r;
	int i, j, k;
	for (i = 0; i < 4; i++)
		for (j = 0; j < 4; j++) {
			r.m[i][j] = 0;
			for (k = 0; k < 4; k++)
				r.m[i][j] += a.m[i][k] * b.m[k][j];
		}
	return r;
}

/* Rotation by angle about unit axis (Rodrigues), then translation t. */
static mat4 m_rot(const double *ax, double a)
{
	double c = cos(a), s = sin(a), C = 1 - c, x = ax[0], y = ax[1], z = ax[2];
	double n = sqrt(x * x + y * y + z * z);
	mat4 r = m_id();
	x /= n;
	y /= n;
	z /= n;
	r.m[0][0] = c + x * x * C;
	r.m[0][1] = x * y * C - z * s;
	r.m[0][2] = x * z * C + y * s;
	r.m[1][0] = y * x * C + z * s;
	r.m[1][1] = c + y * y * C;
	r.m[1][2] = y * z * C - x * s;
	r.m[2][0] = z * x * C - y * s;
	r.m[2][1] = z * y * C + x * s;
	r.m[2][2] = c + z * z * C;
	return r;
}

static mat4 m_trans(double x, double y, double z)
{
	mat4 r = m_id();
	r.m[0][3] = x;
	r.m[1][3] = y;
	r.m[2][3] = z;
	return r;
}

static mat4 m_origin(double x, double y, double z, double ro, double pi, double ya)
{
	static const double X[3] = {1, 0, 0}, Y[3] = {0, 1, 0}, Z[3] = {0, 0, 1};
	return m_mul(m_trans(x, y, z), m_mul(m_rot(Z, ya), m_mul(m_rot(Y, pi), m_rot(X, ro))));
}

/* The arm's link frames for q, written out joint by joint from the
 * URDF text above (base at the identity). */
static void arm_frames(const double *q, mat4 *base, mat4 *l1, mat4 *l2, mat4 *cam,
		       mat4 *l3, mat4 *l4, mat4 *l5, mat4 *l6, mat4 *tool)
{
	static const double Z[3] = {0, 0, 1}, Y[3] = {0, 1, 0}, A3[3] = {0, 1, 1};
	*base = m_id();
	*l1 = m_mul(*base, m_mul(m_origin(0, 0, 0.1, 0, 0, 0), m_rot(Z, q[0])));
	*l2 = m_mul(*l1, m_mul(m_origin(0, 0, 0.2, -M_PI / 2, 0, 0), m_rot(Z, q[1])));
	*cam = m_mul(*l2, m_origin(0.1, 0.05, 0, 0, 0, 0.5));
	*l3 = m_mul(*l2, m_mul(m_origin(0.3, 0, 0, 0.2, 0.1, -0.3), m_rot(A3, q[2])));
	*l4 = m_mul(*l3, m_mul(m_origin(0, 0, 0.1, 0, 0, 0), m_trans(q[3], 0, 0)));
	*l5 = m_mul(*l4, m_mul(m_origin(0, 0, 0.2, 0, 0.4, 0), m_rot(Y, q[4])));
	*l6 = m_mul(*l5, m_mul(m_origin(0, 0, 0.05, 0, 0, 0), m_rot(Z, q[5])));
	*tool = m_mul(*l6, m_mul(m_origin(0, 0, 0.04, 0, 0, 0.7), m_origin(0.01, 0, 0.01, 0, 0, 0)));
}

/* Largest difference between pose p applied to a few points and m. */
static double pose_err(px_pose p, mat4 m)
{
	static const double pts[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
	double worst = 0;
	int i, k;
	for (i = 0; i < 4; i++) {
		px_vec3 a = px_pose_transform_point(p, px_v3(pts[i][0], pts[i][1], pts[i][2]));
		double b[3];
		for (k = 0; k < 3; k++)
			b[k] = m.m[k][0] * pts[i][0] + m.m[k][1] * pts[i][1] +
			       m.m[k][2] * pts[i][2] + m.m[k][3];
		worst = fmax(worst, fabs(a.x - b[0]));
		worst = fmax(worst, fabs(a.y - b[1]));
		worst = fmax(worst, fabs(a.z - b[2]));
	}
	return worst;
}

static void test_reads_the_arm(void)
{
	struct px_urdf *u;
	const struct px_urdf_joint *j;
	const struct px_urdf_link *l;
	PX_NEEDS(XML);
	u = load_arm();
	PX_CHECK(strcmp(px_urdf_name(u), "arm6") == 0);
	PX_CHECK_INT_EQ(px_urdf_link_count(u), 10);
	PX_CHECK_INT_EQ(px_urdf_joint_count(u), 9);
	PX_CHECK_INT_EQ(px_urdf_root(u), px_urdf_find_link(u, "base"));
	j = px_urdf_joint(u, px_urdf_find_joint(u, "j3"));
	PX_CHECK(j && j->type == PX_URDF_CONTINUOUS && isinf(j->lower) && j->lower < 0);
	PX_CHECK_NEAR(j->axis.y, sqrt(0.5), 1e-15);
	j = px_urdf_joint(u, px_urdf_find_joint(u, "j4"));
	PX_CHECK(j && j->type == PX_URDF_PRISMATIC && j->upper == 0.2 && j->velocity == 0.5);
	l = px_urdf_link(u, px_urdf_find_link(u, "link2"));
	PX_CHECK(l && l->n_shapes == 2 && l->shapes[1].type == PX_URDF_SPHERE);
	l = px_urdf_link(u, px_urdf_find_link(u, "link3"));
	PX_CHECK(l && l->shapes[0].type == PX_URDF_MESH && l->shapes[0].mesh &&
		 strstr(l->shapes[0].mesh, "/pkgs/armpkg/meshes/cube.stl"));
	PX_CHECK(l->shapes[0].size[2] == 0.2);
	l = px_urdf_link(u, px_urdf_find_link(u, "link4"));
	PX_CHECK(l && l->shapes[0].mesh && strstr(l->shapes[0].mesh, "/meshes/cube.stl"));
	px_urdf_free(u);
}

/* Every body of the robot against the matrices, over random q. */
static void test_forward_kinematics(void)
{
	struct px_urdf *u;
	struct px_urdf_robot *r;
	struct px_urdf_error e;
	int i, b, rc;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	u = load_arm();
	rc = px_urdf_robot_create(u, "base", "tool", px_pose_identity(), &r, &e);
	PX_CHECK_MSG(rc == PX_OK, "%s", e.msg);
	px_urdf_free(u); /* the robot keeps what it needs */
	PX_CHECK_INT_EQ(px_urdf_robot_dof(r), 6);
	PX_CHECK(strcmp(px_urdf_robot_joint_name(r, 3), "j4") == 0);
	/* base, link1, link2 x2, camera, link3 .. link6, tool: 10 shapes */
	PX_CHECK_INT_EQ(px_urdf_robot_body_count(r), 10);
	for (i = 0; i < 300; i++) {
		double q[6];
		mat4 f[10];
		int k;
		for (k = 0; k < 6; k++)
			q[k] = (k == 3 ? 0.2 : 6.0) * ((double)rand() / RAND_MAX - (k == 3 ? 0 : 0.5));
		PX_CHECK_INT_EQ(px_urdf_robot_set_q(r, q, NULL, 0), PX_OK);
		arm_frames(q, &f[0], &f[1], &f[2], &f[3], &f[4], &f[5], &f[6], &f[7], &f[8]);
		for (b = 0; b < px_urdf_robot_body_count(r); b++) {
			const struct px_urdf_body *bd = px_urdf_robot_body(r, b);
			const char *ln = px_urdf_robot_body_link(r, b);
			static const char *const names[] = {"base",  "link1", "link2",
							    "camera", "link3", "link4",
							    "link5", "link6", "tool"};
			mat4 want = m_id();
			const char *lk = ln;
			int n;
			for (n = 0; n < 9; n++)
				if (!strcmp(names[n], lk))
					want = f[n];
			/* the shape's own origin, from the URDF text */
			if (!strcmp(lk, "base"))
				want = m_mul(want, m_origin(0, 0, 0.05, 0, 0, 0));
			else if (!strcmp(lk, "link1"))
				want = m_mul(want, m_origin(0, 0, 0.1, 0.1, 0, 0.2));
			else if (!strcmp(lk, "link2") && bd->shape == 0)
				want = m_mul(want, m_origin(0.15, 0, 0, 0, M_PI / 2, 0));
			else if (!strcmp(lk, "link2"))
				want = m_mul(want, m_origin(0.3, 0, 0, 0, 0, 0));
			else if (!strcmp(lk, "link3"))
				want = m_mul(want, m_origin(0.01, -0.02, 0.03, 0.3, -0.2, 0.1));
			else if (!strcmp(lk, "link4") || !strcmp(lk, "tool"))
				want = m_mul(want, m_origin(0, 0, !strcmp(lk, "tool") ? 0.05 : 0.1, 0, 0, 0));
			else if (!strcmp(lk, "link6"))
				want = m_mul(want, m_origin(0, 0, 0.02, 0, 0, 0));
			PX_CHECK_MSG(pose_err(px_model_pose(bd->model), want) < 1e-12,
				     "body %d (link %s) off by %g at sample %d", b, lk,
				     pose_err(px_model_pose(bd->model), want), i);
		}
	}
	px_urdf_robot_free(r);
}

/* The shapes' geometry: a box's face, the scaled mesh's extent, the
 * mirrored mesh still signed with the outside out. */
static void test_shapes(void)
{
	struct px_urdf *u;
	struct px_urdf_robot *r;
	struct px_urdf_error e;
	double q[6] = {0};
	int b, seen = 0;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	u = load_arm();
	PX_CHECK_INT_EQ(px_urdf_robot_create(u, NULL, "tool", px_pose_identity(), &r, &e), PX_OK);
	px_urdf_free(u);
	PX_CHECK_INT_EQ(px_urdf_robot_set_q(r, q, NULL, 0), PX_OK);
	for (b = 0; b < px_urdf_robot_body_count(r); b++) {
		const struct px_urdf_body *bd = px_urdf_robot_body(r, b);
		px_pose p = px_model_pose(bd->model);
		struct px_model_result res;
		const char *lk = px_urdf_robot_body_link(r, b);
		if (!strcmp(lk, "link3")) {
			/* the unit cube scaled 0.1 x 0.05 x 0.2: its centre is
			 * inside, 0.025 deep (the thin side) */
			px_vec3 c = px_pose_transform_point(p, px_v3(0.05, 0.025, 0.1));
			PX_CHECK_INT_EQ(px_model_query(bd->model, c, &res), 1);
			PX_CHECK_NEAR(res.distance, -0.025, 1e-9);
			seen++;
		} else if (!strcmp(lk, "link4")) {
			/* mirrored in x: the cube spans x in [-0.05, 0] */
			px_vec3 c = px_pose_transform_point(p, px_v3(-0.025, 0.025, 0.05));
			px_vec3 o = px_pose_transform_point(p, px_v3(0.01, 0.025, 0.05));
			PX_CHECK_INT_EQ(px_model_query(bd->model, c, &res), 1);
			PX_CHECK_NEAR(res.distance, -0.025, 1e-9);
			PX_CHECK_INT_EQ(px_model_query(bd->model, o, &res), 1);
			PX_CHECK_NEAR(res.distance, 0.01, 1e-9);
			seen++;
		} else if (!strcmp(lk, "link1")) {
			/* box 0.08 x 0.1 x 0.2 centred: +x face 0.04 out */
			px_vec3 o = px_pose_transform_point(p, px_v3(0.1, 0, 0));
			PX_CHECK_INT_EQ(px_model_query(bd->model, o, &res), 1);
			PX_CHECK_NEAR(res.distance, 0.06, 1e-12);
			seen++;
		}
	}
	PX_CHECK_INT_EQ(seen, 3);
	px_urdf_robot_free(r);
}

static void test_set_q_no_alloc(void)
{
	struct px_urdf *u;
	struct px_urdf_robot *r;
	struct px_urdf_error e;
	px_pose frames[7];
	uint64_t a;
	int i;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	u = load_arm();
	PX_CHECK_INT_EQ(px_urdf_robot_create(u, "base", "tool", px_pose_identity(), &r, &e), PX_OK);
	px_urdf_free(u);
	a = px_alloc_region_begin();
	for (i = 0; i < 2000; i++) {
		double q[6] = {0.001 * i, -0.002 * i, 0.5, 0.1, 0.3, -0.001 * i};
		PX_CHECK_INT_EQ(px_urdf_robot_set_q(r, q, frames, 7), PX_OK);
	}
	PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
	{
		double bad[6] = {0, NAN, 0, 0, 0, 0};
		PX_CHECK(px_urdf_robot_set_q(r, bad, NULL, 0) < 0);
		PX_CHECK_INT_EQ(px_urdf_robot_set_q(r, bad, frames, 3), PX_E_NOSPC);
	}
	px_urdf_robot_free(r);
}

/* Clearances of every body against a sphere and a point cloud: each
 * pair against point queries (the sphere: its centre's signed distance
 * minus the radius; the cloud: the nearest of its points), cold and
 * coherent along a joint path, no allocation. */
static void test_clearances(void)
{
	struct px_urdf *u;
	struct px_urdf_robot *r;
	struct px_urdf_error e;
	struct px_model *obs[2], *ball, *cloud;
	struct px_prim sp = {PX_PRIM_SPHERE, 0.08, 0, 0};
	struct px_urdf_clearance cl[64], mn;
	double pts[3 * 40];
	px_pose pose = px_pose_identity();
	int i, k, n, nb, checked = 0, certified = 0;
	uint64_t a;
	PX_NEEDS(XML);
	PX_NEEDS(ASSIMP);
	u = load_arm();
	PX_CHECK_INT_EQ(px_urdf_robot_create(u, "base", "tool", px_pose_identity(), &r, &e), PX_OK);
	px_urdf_free(u);
	PX_CHECK_INT_EQ(px_prim_model(&sp, &ball), PX_OK);
	pose.t = px_v3(0.25, 0.1, 0.45);
	PX_CHECK_INT_EQ(px_model_set_pose(ball, pose), PX_OK);
	for (i = 0; i < 40; i++) {
		pts[3 * i] = -0.3 + 0.02 * (i % 8);
		pts[3 * i + 1] = 0.2 + 0.03 * (i / 8);
		pts[3 * i + 2] = 0.3 + 0.01 * (i % 5);
	}
	PX_CHECK_INT_EQ(px_cloud_model(pts, 40, 0.0, NULL, &cloud), PX_OK);
	obs[0] = ball;
	obs[1] = cloud;
	PX_CHECK_INT_EQ(px_urdf_robot_set_obstacles(r, obs, 2), PX_OK);
	nb = px_urdf_robot_body_count(r);
	PX_CHECK(2 * nb <= 64);
	for (i = 0; i < 200; i++) {
		double q[6], t = i / 199.0;
		q[0] = 2.5 * sin(3.1 * t);
		q[1] = -1.0 + 1.5 * t;
		q[2] = 2.0 * cos(2.3 * t);
		q[3] = 0.1 + 0.1 * sin(5 * t);
		q[4] = 1.2 * sin(1.7 * t);
		q[5] = t;
		PX_CHECK_INT_EQ(px_urdf_robot_set_q(r, q, NULL, 0), PX_OK);
		a = px_alloc_region_begin();
		n = px_urdf_robot_clearances(r, NULL, i > 0, cl, 64, &mn);
		PX_CHECK_INT_EQ(px_alloc_region_end(a), 0);
		PX_CHECK_INT_EQ(n, 2 * nb);
		for (k = 0; k < n; k++) {
			const struct px_urdf_body *bd = px_urdf_robot_body(r, cl[k].body);
			struct px_model_result res;
			double ref = INFINITY;
			if (cl[k].obstacle == 0) {
				PX_CHECK_INT_EQ(px_model_query(bd->model, pose.t, &res), 1);
				ref = res.distance - sp.a;
			} else {
				int j;
				for (j = 0; j < 40; j++) {
					PX_CHECK_INT_EQ(px_model_query(bd->model,
								      px_v3(pts[3 * j], pts[3 * j + 1], pts[3 * j + 2]),
								      &res), 1);
					ref = fmin(ref, res.distance);
				}
			}
			PX_CHECK(mn.distance_m <= cl[k].distance_m);
			if (ref <= 1e-6)
				continue; /* touching or inside: the pair's depth, not a distance */
			/* never below the truth; equal where certified */
			PX_CHECK_MSG(cl[k].distance_m >= ref - 1e-9,
				     "step %d body %d (%s) obstacle %d: %.12g below the reference %.12g",
				     i, cl[k].body, px_urdf_robot_body_link(r, cl[k].body),
				     cl[k].obstacle, cl[k].distance_m, ref);
			checked++;
			if (!cl[k].local_only) {
				certified++;
				PX_CHECK_MSG(fabs(cl[k].distance_m - ref) <= 1e-9,
					     "step %d body %d (%s) obstacle %d: %.12g, reference %.12g",
					     i, cl[k].body, px_urdf_robot_body_link(r, cl[k].body),
					     cl[k].obstacle, cl[k].distance_m, ref);
				PX_CHECK(fabs(px_v3_dist(cl[k].point_robot, cl[k].point_obstacle) -
					      cl[k].distance_m) <= 1e-6);
			}
		}
	}
	PX_CHECK_MSG(checked > 1000 && certified * 2 > checked,
		     "%d pairs checked, %d certified", checked, certified);
	PX_CHECK_INT_EQ(px_urdf_robot_clearances(r, NULL, 0, cl, 3, NULL), PX_E_NOSPC);
	px_urdf_robot_free(r);
	px_model_free(ball);
	px_model_free(cloud);
}

/* ---- refusals ---------------------------------------------------------- */

static void refused(const char *what, const char *xml, int code, const char *place)
{
	struct px_urdf *u = NULL;
	struct px_urdf_error e;
	struct px_urdf_opts o;
	char path[400];
	int rc;
	setup_dir();
	snprintf(path, sizeof(path), "%s/bad.urdf", dir);
	write_file(path, xml);
	memset(&o, 0, sizeof(o));
	rc = px_urdf_load(path, &o, &u, &e);
	PX_CHECK_MSG(rc == code && u == NULL, "%s: rc %d (%s), want %d", what, rc, e.msg, code);
	PX_CHECK_MSG(strstr(e.msg, place) != NULL && strstr(e.msg, path) == e.msg,
		     "%s: message '%s' lacks '%s' or the file", what, e.msg, place);
}

#define ROBOT(body) "<robot name='r'>\n" body "</robot>\n"
#define L(n) "<link name='" n "'/>\n"
#define J(n, t, p, c, extra) \
	"<joint name='" n "' type='" t "'><parent link='" p "'/><child link='" c "'/>" extra "</joint>\n"
#define LIM "<limit lower='-1' upper='1'/>"

static void test_refusals(void)
{
	PX_NEEDS(XML);
	refused("not XML", "this is not <xml", PX_E_PARSE, ":1: XML: ");
	refused("not a robot", "<?xml version='1.0'?>\n<sdf/>\n", PX_E_PARSE, ":2: sdf: the document is not a <robot>");
	refused("unknown joint type", ROBOT(L("a") L("b") J("j", "ball", "a", "b", "")), PX_E_PARSE,
		":4: <joint name='j'>: unknown joint type 'ball'");
	refused("floating joint", ROBOT(L("a") L("b") J("j", "floating", "a", "b", "")),
		PX_E_UNSUPPORTED, ":4: <joint name='j'>: unsupported joint type 'floating'");
	refused("revolute without limit", ROBOT(L("a") L("b") J("j", "revolute", "a", "b", "")),
		PX_E_PARSE, ":4: <joint name='j'>: a revolute or prismatic joint needs <limit>");
	refused("bad number", ROBOT(L("a") L("b") J("j", "fixed", "a", "b", "<origin xyz='1 2 x'/>")),
		PX_E_PARSE, ":4: <joint name='j'>: 'xyz' must be finite numbers");
	refused("NaN", ROBOT(L("a") L("b") J("j", "fixed", "a", "b", "<origin xyz='1 nan 0'/>")),
		PX_E_RANGE, ":4: <joint name='j'>: 'xyz'");
	refused("four numbers", ROBOT(L("a") L("b") J("j", "fixed", "a", "b", "<origin rpy='1 0 0 0'/>")),
		PX_E_PARSE, "'rpy' must be three numbers");
	refused("zero axis", ROBOT(L("a") L("b") J("j", "continuous", "a", "b", "<axis xyz='0 0 0'/>")),
		PX_E_RANGE, ":4: <joint name='j'>: the joint axis is zero");
	refused("limits crossed", ROBOT(L("a") L("b") J("j", "revolute", "a", "b", "<limit lower='1' upper='-1'/>")),
		PX_E_RANGE, "lower limit above upper limit");
	refused("unknown link", ROBOT(L("a") J("j", "fixed", "a", "nope", "")), PX_E_INVAL,
		":3: <joint name='j'>: no link named 'nope'");
	refused("two parents", ROBOT(L("a") L("b") L("c") J("j1", "fixed", "a", "c", "") J("j2", "fixed", "b", "c", "")),
		PX_E_INVAL, ":6: <joint name='j2'>: link 'c' already has a parent (joint 'j1')");
	refused("cycle", ROBOT(L("a") L("b") L("c") J("j1", "fixed", "b", "c", "") J("j2", "fixed", "c", "b", "")),
		PX_E_INVAL, "cycle");
	refused("two roots", ROBOT(L("a") L("b")), PX_E_INVAL, ":3: <link name='b'>: a second root");
	refused("duplicate link", ROBOT(L("a") L("a")), PX_E_INVAL,
		":3: <link name='a'>: a second link of this name (the first is on line 2)");
	refused("no links", ROBOT(""), PX_E_PARSE, "no <link>");
	refused("nameless link", ROBOT("<link/>\n"), PX_E_PARSE, ":2: <link>: a <link> needs a 'name'");
	refused("missing mesh", ROBOT("<link name='a'><collision><geometry><mesh filename='nowhere.stl'/></geometry></collision></link>\n"),
		PX_E_NOTFOUND, ":2: <link name='a'>: mesh 'nowhere.stl' not found (tried ");
	refused("package without path", ROBOT("<link name='a'><collision><geometry><mesh filename='package://p/m.stl'/></geometry></collision></link>\n"),
		PX_E_NOTFOUND, "no package path is configured");
	refused("negative box", ROBOT("<link name='a'><collision><geometry><box size='1 -1 1'/></geometry></collision></link>\n"),
		PX_E_RANGE, ":2: <link name='a'>: <box> size must be positive");
	refused("two shapes in one geometry", ROBOT("<link name='a'><collision><geometry><sphere radius='1'/><sphere radius='2'/></geometry></collision></link>\n"),
		PX_E_PARSE, "<geometry> must hold exactly one shape");
	refused("unknown geometry", ROBOT("<link name='a'><collision><geometry><capsule radius='1'/></geometry></collision></link>\n"),
		PX_E_PARSE, "unknown geometry <capsule>");
	refused("collision without geometry", ROBOT("<link name='a'><collision/></link>\n"),
		PX_E_PARSE, "<collision> without <geometry>");
	refused("huge length", ROBOT("<link name='a'><collision><geometry><sphere radius='1e300'/></geometry></collision></link>\n"),
		PX_E_RANGE, "'radius'");
}

static void test_chain_refusals(void)
{
	static const char *xml = ROBOT(L("a") L("b") L("c") J("j1", "continuous", "a", "b", "")
					       J("j2", "continuous", "a", "c", ""));
	struct px_urdf *u;
	struct px_urdf_robot *r = NULL;
	struct px_urdf_error e;
	char big[40000];
	size_t n;
	int i;
	PX_NEEDS(XML);
	PX_CHECK_INT_EQ(px_urdf_load_mem("mem.urdf", xml, strlen(xml), NULL, &u, &e), PX_OK);
	PX_CHECK_INT_EQ(px_urdf_robot_create(u, "b", "c", px_pose_identity(), &r, &e), PX_E_INVAL);
	PX_CHECK_MSG(strstr(e.msg, "'b' is not between the root and 'c'") != NULL, "%s", e.msg);
	PX_CHECK_INT_EQ(px_urdf_robot_create(u, "a", "zz", px_pose_identity(), &r, &e), PX_E_NOTFOUND);
	PX_CHECK(strstr(e.msg, "no link named 'zz'") != NULL);
	PX_CHECK_INT_EQ(px_urdf_robot_create(u, "a", "c", px_pose_identity(), &r, &e), PX_OK);
	PX_CHECK_INT_EQ(px_urdf_robot_dof(r), 1);
	PX_CHECK_INT_EQ(px_urdf_robot_body_count(r), 0);
	px_urdf_robot_free(r);
	px_urdf_free(u);
	/* 17 movable joints in a row: more than a chain holds */
	n = (size_t)snprintf(big, sizeof(big), "<robot name='long'>\n<link name='l0'/>\n");
	for (i = 1; i <= 17; i++)
		n += (size_t)snprintf(big + n, sizeof(big) - n,
				      "<link name='l%d'/><joint name='j%d' type='continuous'>"
				      "<parent link='l%d'/><child link='l%d'/></joint>\n",
				      i, i, i - 1, i);
	n += (size_t)snprintf(big + n, sizeof(big) - n, "</robot>\n");
	PX_CHECK_INT_EQ(px_urdf_load_mem("long.urdf", big, n, NULL, &u, &e), PX_OK);
	PX_CHECK_INT_EQ(px_urdf_robot_create(u, "l0", "l17", px_pose_identity(), &r, &e), PX_E_NOSPC);
	PX_CHECK(strstr(e.msg, "more than 16 movable joints") != NULL);
	px_urdf_free(u);
}

static void cleanup(void)
{
	char cmd[400];
	if (!dir[0])
		return;
	snprintf(cmd, sizeof(cmd), "rm -rf '%s'", dir);
	PX_CHECK(system(cmd) == 0);
}

static void test_cleanup(void)
{
	cleanup();
	PX_CHECK(1);
}

static const struct px_test tests[] = {
	PX_T(test_reads_the_arm), PX_T(test_forward_kinematics), PX_T(test_shapes),
	PX_T(test_set_q_no_alloc), PX_T(test_clearances), PX_T(test_refusals),
	PX_T(test_chain_refusals),
	PX_T(test_cleanup)};
PX_TEST_MAIN(tests)
