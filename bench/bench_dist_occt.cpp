/*
 * The distance core next to OpenCASCADE on the same geometry and the
 * same random points, in one process:
 *  - surfaces: OCCT's correct configuration (GeomAPI_ProjectPointOnSurf,
 *    Init once, Perform per point, plus GeomAPI_ProjectPointOnCurve onto
 *    the four boundary curves and the corners, so its answer is global)
 *    and its fastest one (Extrema tree search, minimum only, no boundary);
 *  - curves: GeomAPI_ProjectPointOnCurve plus the two end points.
 * Prints per-query ns (median, p99, max), the ratios, and how often each
 * answer is farther than the other's by more than 1e-9 of the model size
 * (a wrong branch). Built only when OpenCASCADE's headers are installed.
 */
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <vector>

#include <GeomAPI_ProjectPointOnCurve.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <gp_Pnt.hxx>

#include "px_arena.h"
#include "px_dist.h"
#include "px_nurbs.h"

static unsigned long long rng = 0x2545f4914f6cdd1dull;
static double urand()
{
	rng ^= rng << 13;
	rng ^= rng >> 7;
	rng ^= rng << 17;
	return (double)(rng >> 11) * 0x1.0p-53;
}

static long long now_ns()
{
	timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (long long)ts.tv_sec * 1000000000LL + ts.tv_nsec;
}

/* A point in the box enlarged by a quarter of its size on every side. */
static px_vec3 random_point(px_aabb b)
{
	px_vec3 e = px_v3_scale(px_v3_sub(b.max, b.min), 0.25);
	px_vec3 lo = px_v3_sub(b.min, e), hi = px_v3_add(b.max, e);
	return px_v3(lo.x + (hi.x - lo.x) * urand(), lo.y + (hi.y - lo.y) * urand(),
		     lo.z + (hi.z - lo.z) * urand());
}

static long long timed_query(px_dist_model *m, px_vec3 q, px_dist_result *r)
{
	long long t0 = now_ns();
	px_dist_query(m, q, r);
	return now_ns() - t0;
}

struct timing {
	long long med, p99, max;
};

static timing summarize(std::vector<long long> t)
{
	std::sort(t.begin(), t.end());
	return {t[t.size() / 2], t[t.size() * 99 / 100], t.back()};
}

/* Distinct knots and multiplicities of a full knot vector. */
static void knots_mults(const double *k, int n, std::vector<double> &kv,
			std::vector<int> &mv)
{
	for (int i = 0; i < n; i++) {
		if (kv.empty() || k[i] > kv.back()) {
			kv.push_back(k[i]);
			mv.push_back(1);
		} else {
			mv.back()++;
		}
	}
}

static void report(const char *what, const char *occt_name, const timing &a,
		   const timing &b, int our_wrong, int occt_wrong, int n)
{
	printf("%-26s proxima   ns: median %7lld  p99 %7lld  max %8lld; wrong branch %d/%d\n",
	       what, a.med, a.p99, a.max, our_wrong, n);
	printf("%-26s %-9s ns: median %7lld  p99 %7lld  max %8lld; wrong branch %d/%d\n",
	       "", occt_name, b.med, b.p99, b.max, occt_wrong, n);
	printf("%-26s ratio (OCCT / proxima): median %.1fx  p99 %.1fx\n", "",
	       (double)b.med / (double)a.med, (double)b.p99 / (double)a.p99);
}

static void surface_case(const char *name, int rational)
{
	static unsigned char mem[1 << 16];
	px_arena a;
	px_nurbs_surf sf;
	double k[8] = {0, 0, 0, 0, 1, 1, 1, 1}, xyz[48], w[16];
	px_arena_init(&a, mem, sizeof(mem));
	TColgp_Array2OfPnt poles(1, 4, 1, 4);
	TColStd_Array2OfReal wts(1, 4, 1, 4);
	for (int j = 0; j < 4; j++)
		for (int i = 0; i < 4; i++) {
			int q = j * 4 + i;
			xyz[3 * q] = i / 3.0;
			xyz[3 * q + 1] = j / 3.0;
			xyz[3 * q + 2] = 0.4 * (urand() - 0.5);
			w[q] = rational ? 0.5 + 2.0 * urand() : 1.0;
			poles.SetValue(i + 1, j + 1,
				       gp_Pnt(xyz[3 * q], xyz[3 * q + 1], xyz[3 * q + 2]));
			wts.SetValue(i + 1, j + 1, w[q]);
		}
	px_nurbs_surf_init(&sf, &a, 3, 3, 4, 4, k, 8, k, 8, xyz, w, NULL);
	px_dist_model *m = nullptr;
	if (px_dist_model_create(NULL, 0, &sf, 1, NULL, &m)) {
		printf("%s: prepare failed\n", name);
		return;
	}
	TColStd_Array1OfReal kn(1, 2);
	TColStd_Array1OfInteger mu(1, 2);
	kn(1) = 0;
	kn(2) = 1;
	mu(1) = 4;
	mu(2) = 4;
	Handle(Geom_BSplineSurface) S =
		rational ? new Geom_BSplineSurface(poles, wts, kn, kn, mu, mu, 3, 3)
			 : new Geom_BSplineSurface(poles, kn, kn, mu, mu, 3, 3);
	GeomAPI_ProjectPointOnSurf full, fast;
	full.Init(S, 0, 1, 0, 1);
	fast.Init(S, 0, 1, 0, 1, Extrema_ExtAlgo_Tree);
	fast.SetExtremaFlag(Extrema_ExtFlag_MIN);
	Handle(Geom_Curve) edge[4] = {S->UIso(0), S->UIso(1), S->VIso(0), S->VIso(1)};
	GeomAPI_ProjectPointOnCurve ec[4];
	for (int e = 0; e < 4; e++)
		ec[e].Init(edge[e], 0, 1);
	gp_Pnt corner[4] = {S->Value(0, 0), S->Value(1, 0), S->Value(0, 1), S->Value(1, 1)};

	const int N = 2000;
	std::vector<long long> tp, tf, tq;
	px_dist_info info;
	px_dist_model_info(m, &info);
	double diag = px_aabb_diagonal(&info.bounds), tol = 1e-9 * diag;
	int our_wrong_full = 0, occt_wrong_full = 0, occt_wrong_fast = 0, our_wrong_fast = 0;
	for (int i = 0; i < N; i++) {
		px_vec3 q = random_point(info.bounds);
		gp_Pnt P(q.x, q.y, q.z);
		px_dist_result r;
		tp.push_back(timed_query(m, q, &r));

		double dfull = INFINITY, dfast = INFINITY;
		long long t0 = now_ns();
		try {
			full.Perform(P);
			if (full.NbPoints() > 0)
				dfull = full.LowerDistance();
			for (int k2 = 0; k2 < 4; k2++) {
				ec[k2].Perform(P);
				if (ec[k2].NbPoints() > 0)
					dfull = std::min(dfull, ec[k2].LowerDistance());
				dfull = std::min(dfull, P.Distance(corner[k2]));
			}
		} catch (Standard_Failure &) {
		}
		tf.push_back(now_ns() - t0);
		t0 = now_ns();
		try {
			fast.Perform(P);
			if (fast.NbPoints() > 0)
				dfast = fast.LowerDistance();
		} catch (Standard_Failure &) {
		}
		tq.push_back(now_ns() - t0);
		our_wrong_full += r.dist > dfull + tol;
		occt_wrong_full += dfull > r.dist + tol;
		our_wrong_fast += r.dist > dfast + tol;
		occt_wrong_fast += dfast > r.dist + tol;
	}
	printf("%s\n", name);
	report("  vs OCCT correct (surf+edges)", "OCCT", summarize(tp), summarize(tf),
	       our_wrong_full, occt_wrong_full, N);
	report("  vs OCCT fast (Extrema tree)", "OCCT", summarize(tp), summarize(tq),
	       our_wrong_fast, occt_wrong_fast, N);
	px_dist_model_free(m);
}

static void curve_case(const char *name, int rational)
{
	static unsigned char mem[1 << 16];
	px_arena a;
	px_nurbs_curve c;
	double k[12] = {0, 0, 0, 0, 0.2, 0.4, 0.6, 0.8, 1, 1, 1, 1}, xyz[24], w[8];
	px_arena_init(&a, mem, sizeof(mem));
	TColgp_Array1OfPnt poles(1, 8);
	TColStd_Array1OfReal wts(1, 8);
	for (int i = 0; i < 8; i++) {
		xyz[3 * i] = i / 7.0;
		xyz[3 * i + 1] = urand() - 0.5;
		xyz[3 * i + 2] = 0.5 * (urand() - 0.5);
		w[i] = rational ? 0.3 + 3.0 * urand() : 1.0;
		poles(i + 1) = gp_Pnt(xyz[3 * i], xyz[3 * i + 1], xyz[3 * i + 2]);
		wts(i + 1) = w[i];
	}
	px_nurbs_curve_init(&c, &a, 3, 8, k, 12, xyz, w, NULL);
	px_dist_opts o;
	px_dist_opts_default(&o);
	px_dist_model *m = nullptr;
	if (px_dist_model_create(&c, 1, NULL, 0, &o, &m)) {
		printf("%s: prepare failed\n", name);
		return;
	}
	std::vector<double> kv;
	std::vector<int> mv;
	knots_mults(k, 12, kv, mv);
	TColStd_Array1OfReal kn(1, (int)kv.size());
	TColStd_Array1OfInteger mu(1, (int)kv.size());
	for (size_t i = 0; i < kv.size(); i++) {
		kn((int)i + 1) = kv[i];
		mu((int)i + 1) = mv[i];
	}
	Handle(Geom_BSplineCurve) C = rational ? new Geom_BSplineCurve(poles, wts, kn, mu, 3)
					       : new Geom_BSplineCurve(poles, kn, mu, 3);
	GeomAPI_ProjectPointOnCurve pc;
	pc.Init(C, 0, 1);
	gp_Pnt e0 = C->Value(0), e1 = C->Value(1);
	const int N = 5000;
	std::vector<long long> tp, to;
	px_dist_info info;
	px_dist_model_info(m, &info);
	double diag = px_aabb_diagonal(&info.bounds), tol = 1e-9 * diag;
	int our_wrong = 0, occt_wrong = 0;
	for (int i = 0; i < N; i++) {
		px_vec3 q = random_point(info.bounds);
		gp_Pnt P(q.x, q.y, q.z);
		px_dist_result r;
		tp.push_back(timed_query(m, q, &r));
		double d = std::min(P.Distance(e0), P.Distance(e1));
		long long t0 = now_ns();
		try {
			pc.Perform(P);
			if (pc.NbPoints() > 0)
				d = std::min(d, pc.LowerDistance());
		} catch (Standard_Failure &) {
		}
		to.push_back(now_ns() - t0);
		our_wrong += r.dist > d + tol;
		occt_wrong += d > r.dist + tol;
	}
	printf("%s\n", name);
	report("  vs OCCT (curve+ends)", "OCCT", summarize(tp), summarize(to), our_wrong,
	       occt_wrong, N);
	px_dist_model_free(m);
}

int main()
{
	printf("OpenCASCADE comparison, same points, same process "
	       "(random points in the bounding box enlarged by 25%% per side)\n");
	curve_case("cubic B-spline curve (8 ctrl)", 0);
	curve_case("rational cubic curve (8 ctrl)", 1);
	surface_case("bicubic patch", 0);
	surface_case("rational bicubic patch", 1);
	return 0;
}
