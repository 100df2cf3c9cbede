// fcl_models - FCL 0.7 reference for bench_models: the same torus mesh and
// the same query points (bench/models_common.h), an OBBRSS hierarchy, and
// a sphere of radius 0 as the query point; and for bench_arm its mesh
// pairs ("arm FILE"). Prints "key value" lines that the benchmarks read.
// Built only when Debian's libfcl-dev is installed.
#include <fcl/fcl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <time.h>
#include <vector>

#include "models_common.h"

static double now_ns()
{
	return std::chrono::duration<double, std::nano>(
		       std::chrono::steady_clock::now().time_since_epoch())
		.count();
}

static double run(fcl::CollisionObjectd &mesh, fcl::CollisionObjectd &pt,
		  const std::vector<double> &pts, double *sum)
{
	std::vector<double> t(pts.size() / 3);
	fcl::DistanceRequestd req;
	req.enable_nearest_points = true;
	double s = 0;
	for (size_t i = 0; i < t.size(); i++) {
		fcl::DistanceResultd res;
		double a = now_ns();
		pt.setTranslation(fcl::Vector3d(pts[3 * i], pts[3 * i + 1], pts[3 * i + 2]));
		fcl::distance(&mesh, &pt, req, res);
		t[i] = now_ns() - a;
		s += res.min_distance;
	}
	*sum = s;
	std::sort(t.begin(), t.end());
	return t[t.size() / 2];
}

static std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> fcl_mesh(const struct gen_mesh &g)
{
	std::vector<fcl::Vector3d> v;
	std::vector<fcl::Triangle> tr;
	for (size_t i = 0; i < g.nv; i++)
		v.emplace_back(g.xyz[3 * i], g.xyz[3 * i + 1], g.xyz[3 * i + 2]);
	for (size_t i = 0; i < g.nt; i++)
		tr.emplace_back(g.tri[3 * i], g.tri[3 * i + 1], g.tri[3 * i + 2]);
	auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
	model->beginModel();
	model->addSubModel(v, tr);
	model->endModel();
	return model;
}

// "pair": mesh-to-mesh distance on the pair workload of models_common.h
// (torus 4k against sphere 4k), timed per call like bench_models.
static int run_pair()
{
	struct gen_mesh g1, g2;
	if (gen_torus(0.1, 0.03, 64, 32, &g1) != 0 || gen_sphere(0.08, 32, 64, &g2) != 0)
		return 1;
	fcl::CollisionObjectd a(fcl_mesh(g1), fcl::Transform3d::Identity());
	fcl::CollisionObjectd b(fcl_mesh(g2), fcl::Transform3d::Identity());
	fcl::DistanceRequestd req;
	req.enable_nearest_points = true;
	std::vector<double> t(BM_PAIR_N);
	double sum = 0;
	for (int i = 0; i < BM_PAIR_N; i++) {
		double tr[3], ax[3], ang;
		bm_pair_pose(i, tr, ax, &ang);
		fcl::Transform3d T = fcl::Transform3d::Identity();
		T.linear() = fcl::AngleAxisd(ang, fcl::Vector3d(ax[0], ax[1], ax[2])).toRotationMatrix();
		T.translation() = fcl::Vector3d(tr[0], tr[1], tr[2]);
		b.setTransform(T);
		fcl::DistanceResultd res;
		double s = now_ns();
		fcl::distance(&a, &b, req, res);
		t[i] = now_ns() - s;
		sum += res.min_distance;
	}
	std::sort(t.begin(), t.end());
	std::printf("pair_median_ns %.3f\n", t[t.size() / 2]);
	std::printf("pair_p99_ns %.3f\n", t[(size_t)(0.99 * t.size())]);
	std::printf("pair_sum %.15g\n", sum);
	gen_free(&g1);
	gen_free(&g2);
	return 0;
}

// "arm FILE": bench_arm's mesh workload (its link and obstacle meshes as
// triangle soups, the obstacles' poses, every cycle's link poses):
// every link against every obstacle per cycle, timed per cycle in the
// thread's CPU time as bench_arm does.
static double cpu_ns()
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return ts.tv_sec * 1e9 + ts.tv_nsec;
}

static bool read_pose(FILE *f, fcl::Transform3d *T)
{
	double t[3], q[4];
	if (std::fscanf(f, "%lf %lf %lf %lf %lf %lf %lf", &t[0], &t[1], &t[2], &q[0], &q[1], &q[2],
			&q[3]) != 7)
		return false;
	*T = fcl::Transform3d::Identity();
	T->linear() = fcl::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
	T->translation() = fcl::Vector3d(t[0], t[1], t[2]);
	return true;
}

static std::shared_ptr<fcl::BVHModel<fcl::OBBRSSd>> read_soup(FILE *f)
{
	size_t nt;
	if (std::fscanf(f, "%zu", &nt) != 1)
		return nullptr;
	std::vector<fcl::Vector3d> v;
	std::vector<fcl::Triangle> tr;
	for (size_t i = 0; i < 3 * nt; i++) {
		double x, y, z;
		if (std::fscanf(f, "%lf %lf %lf", &x, &y, &z) != 3)
			return nullptr;
		v.emplace_back(x, y, z);
	}
	for (size_t i = 0; i < nt; i++)
		tr.emplace_back(3 * i, 3 * i + 1, 3 * i + 2);
	auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
	model->beginModel();
	model->addSubModel(v, tr);
	model->endModel();
	return model;
}

static int run_arm(const char *file)
{
	FILE *f = std::fopen(file, "r");
	int nb, no, nc;
	if (!f || std::fscanf(f, "%d %d %d", &nb, &no, &nc) != 3)
		return 1;
	std::vector<std::unique_ptr<fcl::CollisionObjectd>> body, obs;
	for (int i = 0; i < nb + no; i++) {
		auto m = read_soup(f);
		if (!m)
			return 1;
		auto o = std::unique_ptr<fcl::CollisionObjectd>(
			new fcl::CollisionObjectd(m, fcl::Transform3d::Identity()));
		(i < nb ? body : obs).push_back(std::move(o));
	}
	for (int i = 0; i < no; i++) {
		fcl::Transform3d T;
		if (!read_pose(f, &T))
			return 1;
		obs[i]->setTransform(T);
	}
	std::vector<std::vector<fcl::Transform3d>> poses(nc, std::vector<fcl::Transform3d>(nb));
	for (int k = 0; k < nc; k++)
		for (int i = 0; i < nb; i++)
			if (!read_pose(f, &poses[k][i]))
				return 1;
	std::fclose(f);
	fcl::DistanceRequestd req;
	req.enable_nearest_points = true;
	std::vector<double> t(nc), d((size_t)nb * no);
	double sum = 0;
	int over = 0;
	for (int k = 0; k < nc; k++) {
		double s = cpu_ns();
		for (int i = 0; i < nb; i++) {
			body[i]->setTransform(poses[k][i]);
			for (int j = 0; j < no; j++) {
				fcl::DistanceResultd res;
				fcl::distance(body[i].get(), obs[j].get(), req, res);
				d[(size_t)i * no + j] = res.min_distance;
			}
		}
		t[k] = cpu_ns() - s;
		for (double x : d) {
			sum += x > 0 ? x : 0;
			over += x <= 0;
		}
	}
	std::sort(t.begin(), t.end());
	std::printf("arm_median_ns %.3f\n", t[t.size() / 2]);
	std::printf("arm_p99_ns %.3f\n", t[(size_t)(0.99 * t.size())]);
	std::printf("arm_max_ns %.3f\n", t.back());
	std::printf("arm_sum %.15g\n", sum);
	std::printf("arm_overlaps %d\n", over);
	return 0;
}

int main(int argc, char **argv)
{
	if (argc > 1 && std::string(argv[1]) == "pair")
		return run_pair();
	if (argc > 2 && std::string(argv[1]) == "arm")
		return run_arm(argv[2]);
	struct gen_mesh g;
	if (gen_torus(BM_R, BM_r, BM_NU, BM_NV, &g) != 0)
		return 1;
	std::vector<fcl::Vector3d> v;
	std::vector<fcl::Triangle> tr;
	for (size_t i = 0; i < g.nv; i++)
		v.emplace_back(g.xyz[3 * i], g.xyz[3 * i + 1], g.xyz[3 * i + 2]);
	for (size_t i = 0; i < g.nt; i++)
		tr.emplace_back(g.tri[3 * i], g.tri[3 * i + 1], g.tri[3 * i + 2]);
	double t0 = now_ns();
	auto model = std::make_shared<fcl::BVHModel<fcl::OBBRSSd>>();
	model->beginModel();
	model->addSubModel(v, tr);
	model->endModel();
	fcl::CollisionObjectd mesh(model, fcl::Transform3d::Identity());
	std::printf("build_ms %.3f\n", (now_ns() - t0) / 1e6);
	auto sph = std::make_shared<fcl::Sphered>(0.0);
	fcl::CollisionObjectd pt(sph, fcl::Transform3d::Identity());

	std::vector<double> cold(3 * BM_NQ), traj(3 * BM_NQ);
	uint64_t seed = 12345;
	for (int i = 0; i < BM_NQ; i++) {
		bm_cold_point(&seed, i, &cold[3 * i]);
		bm_traj_point(i, &traj[3 * i]);
	}
	double sc, st;
	std::printf("cold_median_ns %.3f\n", run(mesh, pt, cold, &sc));
	std::printf("cold_sum %.15g\n", sc);
	std::printf("traj_median_ns %.3f\n", run(mesh, pt, traj, &st));
	std::printf("traj_sum %.15g\n", st);
	gen_free(&g);
	return 0;
}
