// OpenCASCADE reference for the CAD importer's tests (px_occt_ref.h).
#include <cmath>
#include <vector>

#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepClass3d.hxx>
#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GeomAPI_ProjectPointOnCurve.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array1OfPnt.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Shell.hxx>
#include <TopoDS_Solid.hxx>
#include <gp_Pnt2d.hxx>

#include "px_occt_ref.h"

struct px_occt_ref {
	TopoDS_Shape shape;
	std::vector<TopoDS_Face> faces, conv;
	std::vector<TopoDS_Solid> solids;
	std::vector<Handle(Geom_Curve)> edges;
	std::vector<double> e0, e1;
	int n_solids;
	double size, edge_tol;
};

namespace {

bool read_shape(const char *path, TopoDS_Shape &s)
{
	std::string p(path);
	bool step = p.size() > 4 && (p.substr(p.size() - 5) == ".step" ||
				     p.substr(p.size() - 4) == ".stp");
	Message::DefaultMessenger()->ChangePrinters().Clear();
	if (step) {
		STEPControl_Reader rd;
		Interface_Static::SetCVal("xstep.cascade.unit", "MM");
		if (rd.ReadFile(path) != IFSelect_RetDone || rd.TransferRoots() <= 0)
			return false;
		s = rd.OneShape();
	} else {
		IGESControl_Reader rd;
		Interface_Static::SetCVal("xstep.cascade.unit", "MM");
		if (rd.ReadFile(path) != IFSelect_RetDone || rd.TransferRoots() <= 0)
			return false;
		s = rd.OneShape();
	}
	return !s.IsNull();
}

void add_faces(px_occt_ref &r, const TopoDS_Shape &sh)
{
	for (TopExp_Explorer ex(sh, TopAbs_FACE); ex.More(); ex.Next())
		r.faces.push_back(TopoDS::Face(ex.Current()));
}

// The importer's order: solids (outer shell first), free shells, free
// faces.
void list_faces(px_occt_ref &r, int want)
{
	int k = 0;
	for (TopExp_Explorer ex(r.shape, TopAbs_SOLID); ex.More(); ex.Next(), k++) {
		if (want >= 0 && k != want)
			continue;
		TopoDS_Solid so = TopoDS::Solid(ex.Current());
		r.solids.push_back(so);
		TopoDS_Shell outer = BRepClass3d::OuterShell(so);
		add_faces(r, outer);
		for (TopExp_Explorer sx(so, TopAbs_SHELL); sx.More(); sx.Next())
			if (!sx.Current().IsSame(outer))
				add_faces(r, sx.Current());
	}
	r.n_solids = k;
	if (want >= 0)
		return;
	for (TopExp_Explorer ex(r.shape, TopAbs_SHELL, TopAbs_SOLID); ex.More(); ex.Next())
		add_faces(r, ex.Current());
	for (TopExp_Explorer ex(r.shape, TopAbs_FACE, TopAbs_SHELL); ex.More(); ex.Next())
		r.faces.push_back(TopoDS::Face(ex.Current()));
}

void setup(px_occt_ref &r, int want)
{
	list_faces(r, want);
	BRepBuilderAPI_NurbsConvert nc(r.shape, Standard_True);
	for (const TopoDS_Face &f : r.faces) {
		TopoDS_Face g = TopoDS::Face(nc.ModifiedShape(f));
		g.Orientation(f.Orientation());
		r.conv.push_back(g);
	}
	r.edge_tol = BRep_Tool::MaxTolerance(nc.Shape(), TopAbs_EDGE);
	TopTools_IndexedMapOfShape em;
	TopExp::MapShapes(r.shape, TopAbs_EDGE, em);
	for (int i = 1; i <= em.Extent(); i++) {
		double f, l;
		Handle(Geom_Curve) c = BRep_Tool::Curve(TopoDS::Edge(em(i)), f, l);
		if (c.IsNull())
			continue;
		r.edges.push_back(c);
		r.e0.push_back(f);
		r.e1.push_back(l);
	}
	Bnd_Box b;
	BRepBndLib::Add(r.shape, b);
	double x0, y0, z0, x1, y1, z1;
	b.Get(x0, y0, z0, x1, y1, z1);
	r.size = std::sqrt((x1 - x0) * (x1 - x0) + (y1 - y0) * (y1 - y0) +
			   (z1 - z0) * (z1 - z0));
}

gp_Pnt pnt(const double p[3])
{
	return gp_Pnt(p[0], p[1], p[2]);
}

} // namespace

extern "C" int px_occt_ref_open(const char *path, int solid,
				struct px_occt_ref **out)
{
	*out = nullptr;
	px_occt_ref *r = new px_occt_ref();
	try {
		if (!read_shape(path, r->shape)) {
			delete r;
			return -1;
		}
		setup(*r, solid);
	} catch (const Standard_Failure &) {
		delete r;
		return -2;
	}
	*out = r;
	return 0;
}

extern "C" void px_occt_ref_free(struct px_occt_ref *r)
{
	delete r;
}

extern "C" int px_occt_ref_face_count(const struct px_occt_ref *r)
{
	return (int)r->faces.size();
}

extern "C" int px_occt_ref_solid_count(const struct px_occt_ref *r)
{
	return r->n_solids;
}

extern "C" double px_occt_ref_size(const struct px_occt_ref *r)
{
	return r->size;
}

extern "C" double px_occt_ref_edge_tol(const struct px_occt_ref *r)
{
	return r->edge_tol;
}

extern "C" int px_occt_ref_conv_point(const struct px_occt_ref *r, int k,
				      double u, double v, double p[3])
{
	if (k < 0 || k >= (int)r->conv.size())
		return -1;
	try {
		gp_Pnt q = BRep_Tool::Surface(r->conv[(size_t)k])->Value(u, v);
		p[0] = q.X(), p[1] = q.Y(), p[2] = q.Z();
		return 0;
	} catch (const Standard_Failure &) {
		return -2;
	}
}

extern "C" double px_occt_ref_surf_dist(const struct px_occt_ref *r, int k,
					const double p[3])
{
	if (k < 0 || k >= (int)r->faces.size())
		return -1;
	try {
		GeomAPI_ProjectPointOnSurf pr(pnt(p),
					      BRep_Tool::Surface(r->faces[(size_t)k]));
		return pr.NbPoints() ? pr.LowerDistance() : -3;
	} catch (const Standard_Failure &) {
		return -2;
	}
}

extern "C" int px_occt_ref_face_state(const struct px_occt_ref *r, int k,
				      const double p[3], double tol)
{
	if (k < 0 || k >= (int)r->faces.size())
		return -1;
	try {
		BRepClass_FaceClassifier fc(r->faces[(size_t)k], pnt(p), tol);
		TopAbs_State s = fc.State();
		return s == TopAbs_IN ? 1 : s == TopAbs_ON ? 2 : 0;
	} catch (const Standard_Failure &) {
		return -2;
	}
}

extern "C" double px_occt_ref_edge_dist(const struct px_occt_ref *r,
					const double p[3])
{
	double best = 1e300;
	for (size_t i = 0; i < r->edges.size(); i++) {
		GeomAPI_ProjectPointOnCurve pr(pnt(p), r->edges[i], r->e0[i], r->e1[i]);
		if (pr.NbPoints())
			best = std::min(best, pr.LowerDistance());
		best = std::min(best, pnt(p).Distance(r->edges[i]->Value(r->e0[i])));
		best = std::min(best, pnt(p).Distance(r->edges[i]->Value(r->e1[i])));
	}
	return best;
}

extern "C" double px_occt_ref_gap(const struct px_occt_ref *r, const double p[3],
			       double tol)
{
	double best = px_occt_ref_edge_dist(r, p);
	for (const TopoDS_Face &f : r->faces) {
		try {
			GeomAPI_ProjectPointOnSurf pr(pnt(p), BRep_Tool::Surface(f));
			for (int i = 1; i <= pr.NbPoints(); i++) {
				double u, v;
				if (pr.Distance(i) >= best)
					continue;
				pr.Parameters(i, u, v);
				BRepClass_FaceClassifier fc(f, gp_Pnt2d(u, v), tol);
				if (fc.State() != TopAbs_OUT)
					best = pr.Distance(i);
			}
		} catch (const Standard_Failure &) {
		}
	}
	return best;
}

extern "C" int px_occt_ref_solid_state(const struct px_occt_ref *r,
				       const double p[3], double tol)
{
	int on = 0;
	for (const TopoDS_Solid &s : r->solids) {
		BRepClass3d_SolidClassifier sc(s, pnt(p), tol);
		if (sc.State() == TopAbs_IN)
			return 1;
		on |= sc.State() == TopAbs_ON;
	}
	return on ? 2 : 0;
}

extern "C" double px_occt_ref_curve_dist(const struct px_nurbs_curve *c,
					 const double p[3])
{
	int n = c->n_ctrl, deg = c->degree;
	TColgp_Array1OfPnt poles(1, n);
	TColStd_Array1OfReal w(1, n);
	for (int i = 0; i < n; i++) {
		const double *q = c->pw + 4 * i;
		poles(i + 1) = gp_Pnt(q[0] / q[3], q[1] / q[3], q[2] / q[3]);
		w(i + 1) = q[3];
	}
	// Knots with multiplicities from the flat sequence.
	std::vector<double> kv;
	std::vector<int> km;
	for (int i = 0; i < c->n_knots; i++) {
		if (!kv.empty() && c->knots[i] == kv.back())
			km.back()++;
		else
			kv.push_back(c->knots[i]), km.push_back(1);
	}
	TColStd_Array1OfReal knots(1, (int)kv.size());
	TColStd_Array1OfInteger mults(1, (int)kv.size());
	for (size_t i = 0; i < kv.size(); i++)
		knots((int)i + 1) = kv[i], mults((int)i + 1) = km[i];
	try {
		Handle(Geom_BSplineCurve) b =
			new Geom_BSplineCurve(poles, w, knots, mults, deg);
		double t0 = c->knots[deg], t1 = c->knots[n];
		GeomAPI_ProjectPointOnCurve pr(pnt(p), b, t0, t1);
		double best = std::min(pnt(p).Distance(b->Value(t0)),
				       pnt(p).Distance(b->Value(t1)));
		return pr.NbPoints() ? std::min(best, pr.LowerDistance()) : best;
	} catch (const Standard_Failure &) {
		return -2;
	}
}
