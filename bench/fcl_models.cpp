// fcl_models - FCL 0.7 reference for bench_models: the same torus mesh and
// the same query points (bench/models_common.h), an OBBRSS hierarchy, and
// a sphere of radius 0 as the query point. Prints "key value" lines that
// bench_models reads. Built only when Debian's libfcl-dev is installed.
#include <fcl/fcl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>
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

int main()
{
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
