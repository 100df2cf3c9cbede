/*
 * CAD parts next to OpenCASCADE on the same points, in one process. The
 * parts of proxima-cadgen (filleted_block, plate, bottle with 1 mm
 * walls, sheet, cylsphere) are written to STEP once per run by that
 * tool (so both sides read the same file), then loaded twice: by
 * px_cad + px_brep as a px_model, and by OpenCASCADE's STEP reader as
 * its user would. Per point, interleaved (so both see cold caches):
 *  - proxima: px_model_query(), signed where the part is closed;
 *  - OCCT unsigned: BRepExtrema_DistShapeShape with the part's shells
 *    loaded once (a solid would answer 0 inside it; LoadS1 at setup, per
 *    point LoadS2 of the point as a vertex and Perform; the vertex is
 *    made outside the timed part; minimum only, Extrema_ExtFlag_MIN,
 *    its fastest setting that is still right here);
 *  - OCCT signed: that plus BRepClass3d_SolidClassifier, loaded once,
 *    Perform per point.
 * Points: random in the part's box enlarged by 25 % per side, and near
 * the surface on both sides (a random point of a random face's trimmed
 * domain moved along its normal by 1e-6 to 3e-3 of the part size).
 * Each point's time is its least over three such passes. Prints
 * per-query median, p99 and max in ns, the ratios OCCT / proxima,
 * and wrong answers of either side: where the distances differ by more
 * than 1e-9 of the part size, the larger one is wrong when the smaller
 * one's closest point is a point of the trimmed part (px_occt_ref_gap():
 * projection on the faces as read, within 1e-9 of the part size), else
 * the case is undecided (the first few cases are printed); signs are
 * compared away from the surface (1e-7 of the size), the side of a near
 * point being the one it was made on (random points where the two
 * disagree are undecided).
 *
 *   bench_brep_occt [PREFIX [N]]
 * runs the parts whose name starts with PREFIX with N random points
 * (and N / 2 near ones) each. Built where OpenCASCADE is.
 */
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <unistd.h>
#include <vector>

#include <BRepBuilderAPI_MakeVertex.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepExtrema_DistShapeShape.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TopExp_Explorer.hxx>
#include <BRep_Builder.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Vertex.hxx>

#include "px_brep.h"
#include "px_cad.h"
#include "px_model.h"
#include "px_occt_ref.h"
#include "px_trim.h"

#include "bench_util.h"

struct timing {
	long long med, p99, max;
};

static timing summarize(std::vector<long long> t)
{
	std::sort(t.begin(), t.end());
	return {t[t.size() / 2], t[t.size() * 99 / 100], t.back()};
}

/* A query point in millimetres and, for near points, the side it was
 * made on (1 outside, -1 inside, 0 unknown). */
struct qpoint {
	double p[3];
	int side;
};

/* The part as proxima loads it, and its trimmed domains for sampling. */
struct pxpart {
	px_cad *cad = nullptr;
	px_model *m = nullptr;
	std::vector<px_trim *> trim;
	px_brep_info info;
	double scale = 0.001;
};

static bool px_load(const char *path, pxpart &x, double &setup_ms)
{
	char msg[512];
	px_brep_error err;
	px_brep *b = nullptr;
	long long t0 = now_ns();
	if (px_cad_load(path, NULL, &x.cad, msg, sizeof msg) != PX_OK) {
		printf("%s: px_cad_load: %s\n", path, msg);
		return false;
	}
	const px_brep_desc *d = px_cad_desc(x.cad);
	if (px_brep_create(d, NULL, &err, &b) != PX_OK) {
		printf("%s: px_brep_create: %s\n", path, err.msg);
		return false;
	}
	px_brep_get_info(b, &x.info);
	if (px_model_from_brep(b, &x.m) != PX_OK) {
		printf("%s: px_model_from_brep failed\n", path);
		return false;
	}
	setup_ms = (double)(now_ns() - t0) / 1e6;
	x.scale = d->scale;
	for (int f = 0; f < d->n_faces; f++) {
		px_trim *t = nullptr;
		px_trim_create(d->faces[f].loops, d->faces[f].n_loops, NULL, NULL, &t);
		x.trim.push_back(t);
	}
	return true;
}

static void px_unload(pxpart &x)
{
	for (px_trim *t : x.trim)
		px_trim_free(t);
	px_model_free(x.m);
	px_cad_free(x.cad);
}

/* A point h away from a random point of a random face's trimmed domain
 * along its outward normal (mm). */
static bool near_point(const pxpart &x, double h, qpoint &q)
{
	const px_brep_desc *d = px_cad_desc(x.cad);
	int f = (int)(urand() * d->n_faces);
	const px_nurbs_surf *s = &d->faces[f].surf;
	double u0, u1, v0, v1;
	px_nurbs_surf_domain(s, &u0, &u1, &v0, &v1);
	for (int tries = 0; tries < 200; tries++) {
		double u = u0 + (u1 - u0) * urand(), v = v0 + (v1 - v0) * urand();
		px_nurbs_surf_derivs dd;
		if (!x.trim[(size_t)f] ||
		    px_trim_contains(x.trim[(size_t)f], u, v, NULL) != PX_TRIM_INSIDE)
			continue;
		px_nurbs_surf_eval(s, u, v, 1, &dd);
		px_vec3 n = px_v3_cross(dd.su, dd.sv);
		double len = px_v3_norm(n);
		if (!(len > 0))
			continue;
		n = px_v3_scale(n, (d->faces[f].reversed ? -1.0 : 1.0) / len);
		px_vec3 p = px_v3_madd(dd.s, n, h);
		q.p[0] = p.x, q.p[1] = p.y, q.p[2] = p.z;
		q.side = h > 0 ? 1 : -1;
		return true;
	}
	return false;
}

static TopoDS_Shape occt_read(const char *path)
{
	STEPControl_Reader rd;
	Interface_Static::SetCVal("xstep.cascade.unit", "MM");
	if (rd.ReadFile(path) != IFSelect_RetDone || rd.TransferRoots() <= 0)
		return TopoDS_Shape();
	return rd.OneShape();
}

/* The shells (or faces) of the shape: DistShapeShape answers 0 for a
 * point inside a solid, the distance to its boundary for its shells. */
static TopoDS_Shape boundary(const TopoDS_Shape &s)
{
	TopoDS_Compound c;
	BRep_Builder b;
	b.MakeCompound(c);
	int n = 0;
	for (TopExp_Explorer ex(s, TopAbs_SHELL); ex.More(); ex.Next(), n++)
		b.Add(c, ex.Current());
	for (TopExp_Explorer ex(s, TopAbs_FACE, TopAbs_SHELL); ex.More(); ex.Next(), n++)
		b.Add(c, ex.Current());
	return n ? TopoDS_Shape(c) : s;
}

static void report(const char *what, const timing &a, const char *unit)
{
	printf("  %-30s median %9lld  p99 %9lld  max %10lld %s\n", what, a.med, a.p99,
	       a.max, unit);
}

static const char *filter;
static int NR = 2000;
static const int PASSES = 3;

static void run(const std::string &dir, const char *name)
{
	std::string path = dir + "/" + name + ".step";
	pxpart x;
	double setup_ms = 0;
	if (!px_load(path.c_str(), x, setup_ms)) {
		px_unload(x);
		return;
	}
	long long t0 = now_ns();
	TopoDS_Shape shape = occt_read(path.c_str());
	double occt_load_ms = (double)(now_ns() - t0) / 1e6;
	px_occt_ref *ref = nullptr;
	if (shape.IsNull() || px_occt_ref_open(path.c_str(), -1, &ref) != 0) {
		printf("%s: OpenCASCADE could not read it\n", path.c_str());
		px_unload(x);
		return;
	}
	const px_brep_desc *d = px_cad_desc(x.cad);
	bool closed = x.info.closed != 0;
	double size = px_occt_ref_size(ref), tol = 1e-9 * size;

	std::vector<qpoint> pts;
	{
		px_vec3 lo = px_v3_scale(x.info.bounds.min, 1.0 / x.scale);
		px_vec3 hi = px_v3_scale(x.info.bounds.max, 1.0 / x.scale);
		px_vec3 e = px_v3_scale(px_v3_sub(hi, lo), 0.25);
		lo = px_v3_sub(lo, e);
		hi = px_v3_add(hi, e);
		for (int i = 0; i < NR; i++) {
			qpoint q;
			q.p[0] = lo.x + (hi.x - lo.x) * urand();
			q.p[1] = lo.y + (hi.y - lo.y) * urand();
			q.p[2] = lo.z + (hi.z - lo.z) * urand();
			q.side = 0;
			pts.push_back(q);
		}
		for (int i = 0; i < NR / 2; i++) {
			qpoint q;
			double h = size * std::pow(10.0, -6.0 + 3.5 * urand());
			if (near_point(x, i % 2 ? h : -h, q))
				pts.push_back(q);
		}
	}

	BRepExtrema_DistShapeShape dss;
	dss.LoadS1(boundary(shape));
	dss.SetFlag(Extrema_ExtFlag_MIN);
	BRepClass3d_SolidClassifier cls;
	if (closed)
		cls.Load(shape);
	std::vector<long long> tp(pts.size(), LLONG_MAX), td(tp), ts(tp);
	int px_wrong = 0, oc_wrong = 0, undecided = 0, px_sign = 0, oc_sign = 0;
	int sign_undecided = 0, oc_fail = 0, signs = 0;
	double worst = 0;
	/* the first points warm both sides' code (not timed); each point's
	 * time is its least over the passes (a pass is cold for both: the
	 * other side's query runs in between), so that a preemption of one
	 * query does not count */
	const size_t warm = 50;
	for (int pass = 0; pass < PASSES; pass++)
	for (size_t i = 0; i < pts.size() + warm; i++) {
		const qpoint &q = pts[i < warm ? i % pts.size() : i - warm];
		gp_Pnt P(q.p[0], q.p[1], q.p[2]);
		px_vec3 pm = px_v3(q.p[0] * x.scale, q.p[1] * x.scale, q.p[2] * x.scale);
		px_model_result r;
		TopoDS_Vertex V = BRepBuilderAPI_MakeVertex(P).Vertex();
		long long a = now_ns();
		px_model_query(x.m, pm, &r);
		long long b = now_ns();
		double doc = INFINITY;
		gp_Pnt foot;
		try {
			dss.LoadS2(V);
			if (dss.Perform() && dss.NbSolution() > 0) {
				doc = dss.Value();
				foot = dss.PointOnShape1(1);
			}
		} catch (const Standard_Failure &) {
		}
		long long c = now_ns();
		int oc_in = 0;
		if (closed) {
			try {
				cls.Perform(P, 1e-7 * size);
				oc_in = cls.State() == TopAbs_IN ? 1 : cls.State() == TopAbs_ON ? 2 : 0;
			} catch (const Standard_Failure &) {
				oc_in = -1;
			}
		}
		long long e = now_ns();
		if (i < warm)
			continue;
		tp[i - warm] = std::min(tp[i - warm], b - a);
		td[i - warm] = std::min(td[i - warm], c - b);
		ts[i - warm] = std::min(ts[i - warm], e - b);
		if (pass > 0)
			continue;
		if (!std::isfinite(doc)) {
			oc_fail++;
			oc_wrong++;
			continue;
		}
		double dpx = std::fabs(r.distance) / x.scale;
		worst = std::max(worst, std::fabs(dpx - doc));
		if (std::fabs(dpx - doc) > tol) {
			/* the smaller answer is right when its point is real */
			double fp[3], gap;
			if (dpx < doc) {
				fp[0] = r.point.x / x.scale, fp[1] = r.point.y / x.scale,
				fp[2] = r.point.z / x.scale;
			} else {
				fp[0] = foot.X(), fp[1] = foot.Y(), fp[2] = foot.Z();
			}
			gap = px_occt_ref_gap(ref, fp, tol);
			if (px_wrong + oc_wrong + undecided < 5)
				printf("  apart: p (%.9g %.9g %.9g) mm: proxima %.12g (feature %d "
				       "index %d at %.9g %.9g %.9g), OCCT %.12g (at %.9g %.9g "
				       "%.9g); gap of the smaller %.3g\n",
				       q.p[0], q.p[1], q.p[2], dpx, r.feature, r.index,
				       r.point.x / x.scale, r.point.y / x.scale, r.point.z / x.scale,
				       doc, foot.X(), foot.Y(), foot.Z(), gap);
			if (gap > tol)
				undecided++;
			else if (dpx < doc)
				oc_wrong++;
			else
				px_wrong++;
		}
		if (!closed || std::min(dpx, doc) < 1e-7 * size || oc_in == 2)
			continue;
		signs++;
		int px_in = r.distance < 0, in = oc_in == 1;
		if (q.side) {
			px_sign += px_in != (q.side < 0);
			oc_sign += in != (q.side < 0);
		} else if (px_in != in) {
			sign_undecided++;
		}
	}
	printf("%s: %d faces, %s; setup proxima %.1f ms (px_cad + px_brep), OCCT read "
	       "%.1f ms; size %.1f mm\n",
	       name, d->n_faces, closed ? "closed (signed)" : "open (unsigned)", setup_ms,
	       occt_load_ms, size);
	timing sp = summarize(tp), sd = summarize(td), ss = summarize(ts);
	report(closed ? "proxima signed cold" : "proxima cold", sp, "ns");
	report("OCCT DistShapeShape", sd, "ns");
	if (closed)
		report("OCCT DistShapeShape+classifier", ss, "ns");
	printf("  ratio OCCT unsigned / proxima: median %.0fx  p99 %.0fx\n",
	       (double)sd.med / (double)sp.med, (double)sd.p99 / (double)sp.p99);
	if (closed)
		printf("  ratio OCCT signed / proxima:   median %.0fx  p99 %.0fx\n",
		       (double)ss.med / (double)sp.med, (double)ss.p99 / (double)sp.p99);
	printf("  %zu points (%d random, %zu near); distances apart by > %.1e mm: proxima "
	       "wrong %d, OCCT wrong %d (no answer %d), undecided %d; largest difference "
	       "%.2e mm\n",
	       tp.size(), NR, tp.size() - (size_t)NR, tol, px_wrong, oc_wrong, oc_fail,
	       undecided, worst);
	if (closed)
		printf("  signs (%d points away from the surface): proxima wrong %d, OCCT wrong "
		       "%d, undecided %d\n",
		       signs, px_sign, oc_sign, sign_undecided);
	px_occt_ref_free(ref);
	px_unload(x);
}

int main(int argc, char **argv)
{
	static const char *const parts[] = {"filleted_block", "plate", "bottle", "sheet",
					    "cylsphere"};
	char exe[512], dir[] = "/tmp/px_bench_cad_XXXXXX";
	if (argc > 1 && argv[1][0])
		filter = argv[1];
	if (argc > 2)
		NR = std::max(10, atoi(argv[2]));
	ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
	if (n <= 0 || !mkdtemp(dir)) {
		printf("bench_brep_occt: no work directory\n");
		return 1;
	}
	exe[n] = 0;
	*strrchr(exe, '/') = 0;
	std::string cmd = std::string("'") + exe + "/../bin/proxima-cadgen' --format step '" +
			  dir + "'";
	for (const char *p : parts)
		cmd += std::string(" ") + p;
	if (system(cmd.c_str()) != 0) {
		printf("bench_brep_occt: %s failed\n", cmd.c_str());
		return 1;
	}
	Message::DefaultMessenger()->ChangePrinters().Clear();
	printf("STEP parts of proxima-cadgen, proxima (px_cad + px_brep) next to OpenCASCADE "
	       "on the same points, same process; ns per query\n");
	for (const char *p : parts)
		if (!filter || !strncmp(p, filter, strlen(filter)))
			run(dir, p);
	std::string rm = std::string("rm -rf '") + dir + "'";
	if (system(rm.c_str()) != 0)
		printf("bench_brep_occt: could not remove %s\n", dir);
	return 0;
}
