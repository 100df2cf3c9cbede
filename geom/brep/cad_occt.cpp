// STEP and IGES import through OpenCASCADE (px_cad.h): read, convert
// every face to NURBS with its loops in the converted surface's own
// parameters, collect edges, vertices, shells and solids into a
// px_brep_desc the handle owns. Nothing of OpenCASCADE leaves this file;
// every exception stops at the C functions.
#include <sys/stat.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <algorithm>
#include <deque>
#include <exception>
#include <mutex>
#include <new>
#include <string>
#include <vector>

#include <BRepBuilderAPI_NurbsConvert.hxx>
#include <BRepClass3d.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <Geom2dConvert.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomConvert.hxx>
#include <GeomConvert_ApproxCurve.hxx>
#include <Geom2dConvert_ApproxCurve.hxx>
#include <Geom_BSplineCurve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_TrimmedCurve.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Check.hxx>
#include <Interface_CheckIterator.hxx>
#include <Interface_InterfaceModel.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_Printer.hxx>
#include <STEPControl_Reader.hxx>
#include <Standard_Failure.hxx>
#include <TCollection_HAsciiString.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_DataMapOfShapeInteger.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TransferBRep.hxx>
#include <Transfer_TransientProcess.hxx>
#include <XSControl_TransferReader.hxx>
#include <XSControl_WorkSession.hxx>

#include "px_cad.h"
#include "px_trim.h"

namespace {

// A refusal: the code and the sentence (without the file name, which
// the C boundary puts in front).
struct refusal {
	int code;
	std::string what;
};

[[noreturn]] void refuse(int code, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));

void refuse(int code, const char *fmt, ...)
{
	char buf[512];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(buf, sizeof buf, fmt, ap);
	va_end(ap);
	throw refusal{code, buf};
}

// Collects what the reader prints (syntax errors carry their line), so
// that a refusal can quote it and nothing reaches the console.
class capture_printer : public Message_Printer {
public:
	mutable std::string fails;

protected:
	void send(const TCollection_AsciiString &s,
		  const Message_Gravity g) const override
	{
		if (g < Message_Fail || fails.size() > 400)
			return;
		// The reader frames its messages in asterisks and lines.
		std::string t(s.ToCString());
		for (char &ch : t)
			if (ch == '\n' || ch == '\r' || ch == '\t')
				ch = ' ';
		size_t a = t.find_first_not_of("* "), b = t.find_last_not_of("* ");
		if (a == std::string::npos)
			return;
		if (!fails.empty())
			fails += "; ";
		fails += t.substr(a, b - a + 1);
	}
};

// Swaps the default messenger's printers for a capture while a file is
// read, and puts them back.
class quiet_messenger {
public:
	Handle(capture_printer) cap = new capture_printer;

	quiet_messenger()
	{
		Message_SequenceOfPrinters &p =
			Message::DefaultMessenger()->ChangePrinters();
		saved_ = p;
		p.Clear();
		p.Append(cap);
	}
	~quiet_messenger()
	{
		Message::DefaultMessenger()->ChangePrinters() = saved_;
	}

private:
	Message_SequenceOfPrinters saved_;
};

// The reader's session unit (a process-wide setting) is millimetres
// while a file is read, then what it was.
class session_unit_mm {
public:
	session_unit_mm()
	{
		Standard_CString u = Interface_Static::CVal("xstep.cascade.unit");
		saved_ = u ? u : "";
		Interface_Static::SetCVal("xstep.cascade.unit", "MM");
	}
	~session_unit_mm()
	{
		if (!saved_.empty())
			Interface_Static::SetCVal("xstep.cascade.unit",
						  saved_.c_str());
	}

private:
	std::string saved_;
};

std::mutex load_lock;

} // namespace

// The handle: the description and the storage its pointers refer to.
// Deques keep element addresses fixed while they grow.
struct px_cad {
	px_brep_desc desc;
	int n_solids_file;
	std::deque<std::vector<double>> reals;
	std::deque<std::vector<px_nurbs_curve>> curves;
	std::deque<std::vector<unsigned char>> flags;
	std::deque<std::vector<px_brep_coedge>> coedges;
	std::deque<std::vector<const px_brep_coedge *>> coedge_lists;
	std::deque<std::vector<px_trim_loop>> loops;
	std::vector<px_brep_face_desc> faces;
	std::vector<px_brep_edge_desc> edges;
	std::vector<px_vec3> vertices;
	std::vector<px_brep_shell_desc> shells;
	std::string name, source;
};

namespace {

enum cad_format { FMT_STEP, FMT_IGES };

bool ends_with_ci(const std::string &s, const char *suf)
{
	size_t n = strlen(suf);
	if (s.size() < n)
		return false;
	for (size_t i = 0; i < n; i++)
		if (tolower((unsigned char)s[s.size() - n + i]) != suf[i])
			return false;
	return true;
}

// By extension, else by the first line (STEP files start with
// "ISO-10303-21"; anything else is tried as IGES).
cad_format guess_format(const std::string &path)
{
	if (ends_with_ci(path, ".step") || ends_with_ci(path, ".stp"))
		return FMT_STEP;
	if (ends_with_ci(path, ".iges") || ends_with_ci(path, ".igs"))
		return FMT_IGES;
	char head[16] = {0};
	FILE *f = fopen(path.c_str(), "rb");
	if (f) {
		size_t n = fread(head, 1, sizeof head - 1, f);
		head[n] = 0;
		fclose(f);
	}
	return strncmp(head, "ISO-10303-21", 12) == 0 ? FMT_STEP : FMT_IGES;
}

void check_file(const std::string &path, size_t max_bytes)
{
	struct stat st;
	if (stat(path.c_str(), &st) != 0)
		refuse(errno == ENOENT ? PX_E_NOTFOUND : PX_E_IO, "%s",
		       strerror(errno));
	if (!S_ISREG(st.st_mode))
		refuse(PX_E_IO, "not a regular file");
	if ((unsigned long long)st.st_size > max_bytes)
		refuse(PX_E_RANGE, "file of %lld bytes is larger than the "
		       "limit of %zu", (long long)st.st_size, max_bytes);
	if (st.st_size == 0)
		refuse(PX_E_PARSE, "empty file");
	FILE *f = fopen(path.c_str(), "rb");
	if (!f)
		refuse(PX_E_IO, "%s", strerror(errno));
	fclose(f);
}

// The file's label of an entity ("#12" for STEP, "D23" for IGES).
std::string entity_label(const Handle(Interface_InterfaceModel) &model,
			 const Handle(Standard_Transient) &ent)
{
	if (model.IsNull() || ent.IsNull() || model->Number(ent) <= 0)
		return std::string();
	Handle(TCollection_HAsciiString) s = model->StringLabel(ent);
	return s.IsNull() ? std::string() : std::string(s->ToCString());
}

long label_number(const std::string &label)
{
	for (size_t i = 0; i < label.size(); i++)
		if (isdigit((unsigned char)label[i]))
			return strtol(label.c_str() + i, nullptr, 10);
	return 0;
}

// First failure of a check list, with the entity it concerns.
bool first_fail(const Interface_CheckIterator &list,
		const Handle(Interface_InterfaceModel) &model,
		std::string &out)
{
	for (list.Start(); list.More(); list.Next()) {
		const Handle(Interface_Check) &ch = list.Value();
		if (ch.IsNull() || !ch->HasFailed())
			continue;
		int num = list.Number();
		std::string where;
		if (num > 0 && !model.IsNull() && num <= model->NbEntities())
			where = entity_label(model, model->Value(num));
		else if (num > 0)
			where = "entity " + std::to_string(num);
		out = (where.empty() ? std::string() : where + ": ") +
		      ch->CFail(1);
		return true;
	}
	return false;
}

// Reads the file with the reader of its format; refuses on any failure
// the reader reports. Leaves the transferred shape in shape and a map
// from the faces and edges it made (unplaced) to their entity labels.
struct read_result {
	TopoDS_Shape shape;
	std::vector<std::string> labels;
	TopTools_DataMapOfShapeInteger shape_label;
};

template <class Reader>
void read_with(Reader &reader, const std::string &path, read_result &rr)
{
	quiet_messenger quiet;
	// Coordinates come back in millimetres whatever the file's unit.
	session_unit_mm mm;
	IFSelect_ReturnStatus st = reader.ReadFile(path.c_str());
	Handle(Interface_InterfaceModel) model = reader.Model();
	std::string fail;
	if (!model.IsNull() &&
	    first_fail(reader.WS()->ModelCheckList(), model, fail))
		refuse(PX_E_PARSE, "%s", fail.c_str());
	if (st != IFSelect_RetDone || model.IsNull()) {
		const std::string &c = quiet.cap->fails;
		refuse(PX_E_PARSE, "the reader cannot parse it%s%s",
		       c.empty() ? "" : ": ", c.c_str());
	}
	if (reader.TransferRoots() <= 0)
		refuse(PX_E_PARSE, "no shape in the file%s%s",
		       quiet.cap->fails.empty() ? "" : ": ",
		       quiet.cap->fails.c_str());
	Handle(Transfer_TransientProcess) tp =
		reader.WS()->TransferReader()->TransientProcess();
	if (!tp.IsNull() && first_fail(tp->CheckList(Standard_False),
				       model, fail))
		refuse(PX_E_PARSE, "%s", fail.c_str());
	rr.shape = reader.OneShape();
	if (rr.shape.IsNull())
		refuse(PX_E_PARSE, "no shape in the file");
	// Every face and edge the reader made with the entity it came from,
	// without placement: an assembly places the same face in each
	// instance (faces its healing replaced have no entity).
	for (int i = 1; !tp.IsNull() && i <= tp->NbMapped(); i++) {
		TopoDS_Shape r = TransferBRep::ShapeResult(tp, tp->Mapped(i));
		if (r.IsNull() || (r.ShapeType() != TopAbs_FACE &&
				   r.ShapeType() != TopAbs_EDGE))
			continue;
		r.Location(TopLoc_Location());
		if (rr.shape_label.IsBound(r))
			continue;
		rr.labels.push_back(entity_label(model, tp->Mapped(i)));
		rr.shape_label.Bind(r, (int)rr.labels.size() - 1);
	}
}

void read_file(const std::string &path, read_result &rr)
{
	if (guess_format(path) == FMT_STEP) {
		STEPControl_Reader reader;
		read_with(reader, path, rr);
	} else {
		IGESControl_Reader reader;
		read_with(reader, path, rr);
	}
}

// ---- conversion ------------------------------------------------------

// The converted shape and the labels moved onto its faces and edges.
struct model_src {
	TopoDS_Shape shape;
	TopTools_DataMapOfShapeInteger shape_label;
	std::vector<std::string> labels;
	TopTools_IndexedMapOfShape edge_map, vertex_map;
	std::vector<int> edge_index; // edge_map index - 1 -> desc edge, -1
};

void convert(const read_result &rr, model_src &m)
{
	BRepBuilderAPI_NurbsConvert nc(rr.shape, Standard_True);
	if (!nc.IsDone())
		refuse(PX_E_UNSUPPORTED, "conversion to NURBS failed");
	m.shape = nc.Shape();
	m.labels = rr.labels;
	TopTools_IndexedMapOfShape subs;
	TopExp::MapShapes(rr.shape, TopAbs_FACE, subs);
	TopExp::MapShapes(rr.shape, TopAbs_EDGE, subs);
	for (int i = 1; i <= subs.Extent(); i++) {
		TopoDS_Shape key = subs(i);
		key.Location(TopLoc_Location());
		int li;
		if (!rr.shape_label.Find(key, li))
			continue;
		TopoDS_Shape nf = nc.ModifiedShape(subs(i));
		if (!nf.IsNull())
			m.shape_label.Bind(nf, li);
	}
	TopExp::MapShapes(m.shape, TopAbs_EDGE, m.edge_map);
	TopExp::MapShapes(m.shape, TopAbs_VERTEX, m.vertex_map);
	m.edge_index.assign((size_t)m.edge_map.Extent(), -2);
}

// A converted face's name for messages.
std::string face_name(const model_src &m, const TopoDS_Face &f, int k)
{
	int li;
	if (m.shape_label.Find(f, li) && !m.labels[(size_t)li].empty())
		return "face " + m.labels[(size_t)li];
	return "face " + std::to_string(k) + " (no entity)";
}

long shape_id(const model_src &m, const TopoDS_Shape &s)
{
	int li;
	if (m.shape_label.Find(s, li))
		return label_number(m.labels[(size_t)li]);
	return 0;
}

std::vector<double> &new_reals(px_cad &c, size_t n)
{
	c.reals.emplace_back(n, 0.0);
	return c.reals.back();
}

// A 2D or 3D B-spline curve as a px_nurbs_curve (2D with z = 0).
template <class BS, class P>
px_nurbs_curve curve_of(px_cad &c, const Handle(BS) &b, int dim,
			const std::string &who)
{
	if (b->IsPeriodic())
		b->SetNotPeriodic();
	int p = b->Degree(), n = b->NbPoles();
	if (p > PX_NURBS_MAX_DEGREE)
		refuse(PX_E_UNSUPPORTED, "%s: curve of degree %d (at most %d)",
		       who.c_str(), p, PX_NURBS_MAX_DEGREE);
	std::vector<double> &kn = new_reals(c, (size_t)(n + p + 1));
	const TColStd_Array1OfReal &seq = b->KnotSequence();
	for (int i = 0; i < n + p + 1; i++)
		kn[(size_t)i] = seq(seq.Lower() + i);
	std::vector<double> &pw = new_reals(c, (size_t)(4 * n));
	for (int i = 0; i < n; i++) {
		P q = b->Pole(i + 1);
		double w = b->Weight(i + 1), xyz[3] = {q.X(), q.Y(), 0.0};
		if (dim == 3)
			xyz[2] = q.Coord(3);
		for (int k = 0; k < 3; k++)
			pw[(size_t)(4 * i + k)] = xyz[k] * w;
		pw[(size_t)(4 * i + 3)] = w;
	}
	px_nurbs_curve out;
	px_nurbs_error err;
	int rc = px_nurbs_curve_view(&out, p, n, kn.data(), n + p + 1,
				     pw.data(), &err);
	if (rc != PX_OK)
		refuse(rc, "%s: %s", who.c_str(), err.msg);
	return out;
}

// A curve above the kernel's degree (the reader's own fits of edge
// curves go up to 14), approximated within tol with the same
// parameter; left as it is when that fails (curve_of() refuses it).
Handle(Geom_BSplineCurve) within_degree(const Handle(Geom_BSplineCurve) &b,
					double tol)
{
	if (b->Degree() <= PX_NURBS_MAX_DEGREE)
		return b;
	GeomConvert_ApproxCurve ap(b, tol, GeomAbs_C2, 1000,
				   PX_NURBS_MAX_DEGREE - 1);
	return ap.HasResult() && ap.MaxError() <= tol ? ap.Curve() : b;
}

Handle(Geom2d_BSplineCurve)
within_degree(const Handle(Geom2d_BSplineCurve) &b, double tol)
{
	if (b->Degree() <= PX_NURBS_MAX_DEGREE)
		return b;
	Geom2dConvert_ApproxCurve ap(b, tol, GeomAbs_C2, 1000,
				     PX_NURBS_MAX_DEGREE - 1);
	return ap.HasResult() && ap.MaxError() <= tol ? ap.Curve() : b;
}

// An edge's tolerance, at least the reader's default precision.
double edge_tol(const TopoDS_Edge &e)
{
	return std::max(BRep_Tool::Tolerance(e), 1e-7);
}

// The desc edge of a converted edge, made on first use (-1: degenerate
// or without a 3D curve).
int edge_of(px_cad &c, model_src &m, const TopoDS_Edge &e)
{
	int k = m.edge_map.FindIndex(e);
	if (k <= 0)
		refuse(PX_E_PARSE, "an edge outside the shape's edge list");
	int &slot = m.edge_index[(size_t)(k - 1)];
	if (slot != -2)
		return slot;
	slot = -1;
	if (BRep_Tool::Degenerated(e))
		return slot;
	double f, l;
	Handle(Geom_Curve) g = BRep_Tool::Curve(e, f, l);
	if (g.IsNull())
		return slot;
	Handle(Geom_BSplineCurve) b = within_degree(
		GeomConvert::CurveToBSplineCurve(new Geom_TrimmedCurve(g, f, l)),
		edge_tol(e));
	px_brep_edge_desc ed;
	ed.id = shape_id(m, e);
	ed.curve = curve_of<Geom_BSplineCurve, gp_Pnt>(
		c, b, 3, ed.id ? "edge " + m.labels[(size_t)m.shape_label.Find(e)]
			       : "edge " + std::to_string(k) + " (no entity)");
	TopoDS_Vertex v0, v1;
	TopExp::Vertices(TopoDS::Edge(e.Oriented(TopAbs_FORWARD)), v0, v1);
	ed.v0 = v0.IsNull() ? -1 : m.vertex_map.FindIndex(v0) - 1;
	ed.v1 = v1.IsNull() ? -1 : m.vertex_map.FindIndex(v1) - 1;
	c.edges.push_back(ed);
	slot = (int)c.edges.size() - 1;
	return slot;
}

// The face's surface as exact NURBS; a periodic surface is cut to the
// window of one period that holds the face.
px_nurbs_surf surface_of(px_cad &c, const TopoDS_Face &f,
			 const std::string &who)
{
	Handle(Geom_Surface) g = BRep_Tool::Surface(f);
	if (g.IsNull())
		refuse(PX_E_PARSE, "%s has no surface", who.c_str());
	Handle(Geom_BSplineSurface) b =
		Handle(Geom_BSplineSurface)::DownCast(g->Copy());
	if (b.IsNull())
		b = GeomConvert::SurfaceToBSplineSurface(g);
	if (b->IsUPeriodic() || b->IsVPeriodic()) {
		double u0, u1, v0, v1, su0, su1, sv0, sv1;
		BRepTools::UVBounds(f, u0, u1, v0, v1);
		b->Bounds(su0, su1, sv0, sv1);
		if (!b->IsUPeriodic())
			u0 = std::max(u0, su0), u1 = std::min(u1, su1);
		else if (u1 - u0 > b->UPeriod())
			u1 = u0 + b->UPeriod();
		if (!b->IsVPeriodic())
			v0 = std::max(v0, sv0), v1 = std::min(v1, sv1);
		else if (v1 - v0 > b->VPeriod())
			v1 = v0 + b->VPeriod();
		b->Segment(u0, u1, v0, v1);
		if (b->IsUPeriodic())
			b->SetUNotPeriodic();
		if (b->IsVPeriodic())
			b->SetVNotPeriodic();
	}
	int pu = b->UDegree(), pv = b->VDegree();
	int nu = b->NbUPoles(), nv = b->NbVPoles();
	if (pu > PX_NURBS_MAX_DEGREE || pv > PX_NURBS_MAX_DEGREE)
		refuse(PX_E_UNSUPPORTED, "%s: surface of degree %d x %d (at "
		       "most %d)", who.c_str(), pu, pv, PX_NURBS_MAX_DEGREE);
	std::vector<double> &ku = new_reals(c, (size_t)(nu + pu + 1));
	std::vector<double> &kv = new_reals(c, (size_t)(nv + pv + 1));
	const TColStd_Array1OfReal &su = b->UKnotSequence();
	const TColStd_Array1OfReal &sv = b->VKnotSequence();
	for (int i = 0; i < nu + pu + 1; i++)
		ku[(size_t)i] = su(su.Lower() + i);
	for (int i = 0; i < nv + pv + 1; i++)
		kv[(size_t)i] = sv(sv.Lower() + i);
	std::vector<double> &pw = new_reals(c, (size_t)(4 * nu * nv));
	for (int j = 0; j < nv; j++)
		for (int i = 0; i < nu; i++) {
			gp_Pnt q = b->Pole(i + 1, j + 1);
			double w = b->Weight(i + 1, j + 1);
			double *d = &pw[(size_t)(4 * (j * nu + i))];
			d[0] = q.X() * w;
			d[1] = q.Y() * w;
			d[2] = q.Z() * w;
			d[3] = w;
		}
	px_nurbs_surf out;
	px_nurbs_error err;
	int rc = px_nurbs_surf_view(&out, pu, pv, nu, nv, ku.data(), nu + pu + 1,
				    kv.data(), nv + pv + 1, pw.data(), &err);
	if (rc != PX_OK)
		refuse(rc, "%s: surface: %s", who.c_str(), err.msg);
	return out;
}

// Where curve k of a loop starts (end = 0) or ends (end = 1), in the
// loop's direction.
px_vec3 loop_point(const std::vector<px_nurbs_curve> &cv,
		   const std::vector<unsigned char> &rev, size_t k, int end)
{
	double t0, t1;
	px_nurbs_curve_domain(&cv[k], &t0, &t1);
	return px_nurbs_curve_point(&cv[k], (end != 0) != (rev[k] != 0) ? t1 : t0);
}

// An edge collapsed to a pole spans, in the parameter plane, the gap
// its neighbours leave, which the file's curve need not match exactly
// (only its 3D image, the pole, is fixed): it becomes the segment from
// the previous curve's end to the next one's start.
void close_poles(px_cad &c, std::vector<px_nurbs_curve> &cv,
		 std::vector<unsigned char> &rev, const std::vector<char> &degen)
{
	size_t n = cv.size();
	for (size_t k = 0; k < n && n > 1; k++) {
		if (!degen[k])
			continue;
		px_vec3 a = loop_point(cv, rev, (k + n - 1) % n, 1);
		px_vec3 b = loop_point(cv, rev, (k + 1) % n, 0);
		double t0, t1;
		px_nurbs_curve_domain(&cv[k], &t0, &t1);
		std::vector<double> &kn = new_reals(c, 4);
		std::vector<double> &pw = new_reals(c, 8);
		kn[0] = kn[1] = t0;
		kn[2] = kn[3] = t1;
		const double q[8] = {a.x, a.y, 0, 1, b.x, b.y, 0, 1};
		std::copy(q, q + 8, pw.begin());
		px_nurbs_error err;
		int rc = px_nurbs_curve_view(&cv[k], 1, 2, kn.data(), 4,
					     pw.data(), &err);
		if (rc != PX_OK)
			refuse(rc, "a curve at a pole: %s", err.msg);
		rev[k] = 0;
	}
}

// A loop curve that leaves the surface's parameter domain (the reader's
// curves may, where an edge runs into a pole and any u is the same
// point) gets its control points clamped into the domain, when the
// surface then still follows the edge's 3D curve within twice the
// edge's tolerance; otherwise the face is refused.
void clamp_to_surface(px_cad &c, px_nurbs_curve &pc, const px_nurbs_surf &s,
		      const TopoDS_Edge &e, const std::string &who)
{
	double u0, u1, v0, v1, worst = 0, out = 0;
	px_nurbs_surf_domain(&s, &u0, &u1, &v0, &v1);
	// Control points may lie outside where the curve does not (a
	// rational arc's do): the curve itself is what must stay inside.
	double a0, a1;
	px_nurbs_curve_domain(&pc, &a0, &a1);
	for (int i = 0; i <= 512; i++) {
		px_vec3 q = px_nurbs_curve_point(&pc, a0 + (a1 - a0) * i / 512.0);
		out = std::max({out, u0 - q.x, q.x - u1, v0 - q.y, q.y - v1});
	}
	if (out <= 1e-9 * std::hypot(u1 - u0, v1 - v0))
		return;
	int n = pc.n_ctrl;
	std::vector<double> &pw = new_reals(c, (size_t)(4 * n));
	bool moved = false;
	for (int i = 0; i < n; i++) {
		double w = pc.pw[4 * i + 3], x = pc.pw[4 * i] / w;
		double y = pc.pw[4 * i + 1] / w;
		double cx = std::min(std::max(x, u0), u1);
		double cy = std::min(std::max(y, v0), v1);
		moved = moved || cx != x || cy != y;
		pw[(size_t)(4 * i)] = cx * w;
		pw[(size_t)(4 * i + 1)] = cy * w;
		pw[(size_t)(4 * i + 2)] = 0.0;
		pw[(size_t)(4 * i + 3)] = w;
	}
	if (!moved)
		return;
	px_nurbs_curve in;
	px_nurbs_error err;
	int rc = px_nurbs_curve_view(&in, pc.degree, n, pc.knots, pc.n_knots,
				     pw.data(), &err);
	if (rc != PX_OK)
		refuse(rc, "%s: %s", who.c_str(), err.msg);
	double f, l, t0, t1;
	Handle(Geom_Curve) g = BRep_Tool::Degenerated(e) ? Handle(Geom_Curve)()
							: BRep_Tool::Curve(e, f, l);
	px_nurbs_curve_domain(&in, &t0, &t1);
	for (int i = 0; !g.IsNull() && i <= 64; i++) {
		double t = t0 + (t1 - t0) * i / 64.0;
		px_vec3 uv = px_nurbs_curve_point(&in, t);
		px_vec3 p = px_nurbs_surf_point(&s, uv.x, uv.y);
		gp_Pnt q = g->Value(f + (l - f) * (t - t0) / (t1 - t0));
		worst = std::max(worst, q.Distance(gp_Pnt(p.x, p.y, p.z)));
	}
	if (worst > 2 * edge_tol(e))
		refuse(PX_E_UNSUPPORTED, "%s leaves the surface's domain [%g, "
		       "%g] x [%g, %g], %g from its edge when brought inside",
		       who.c_str(), u0, u1, v0, v1, worst);
	pc = in;
}

// One wire as a trimming loop: its edges in order (BRepTools_WireExplorer
// follows the connection), each curve on the surface with its direction
// and its edge.
px_trim_loop loop_of(px_cad &c, model_src &m, const TopoDS_Face &f,
		     const px_nurbs_surf &s, const TopoDS_Wire &w,
		     const std::string &who, const px_brep_coedge **coedges)
{
	GeomAdaptor_Surface gs(BRep_Tool::Surface(f));
	int n_all = 0;
	for (TopExp_Explorer ex(w, TopAbs_EDGE); ex.More(); ex.Next())
		n_all++;
	c.curves.emplace_back();
	c.flags.emplace_back();
	c.coedges.emplace_back();
	std::vector<px_nurbs_curve> &cv = c.curves.back();
	std::vector<unsigned char> &rev = c.flags.back();
	std::vector<px_brep_coedge> &ce = c.coedges.back();
	std::vector<char> degen;
	for (BRepTools_WireExplorer wx(w, f); wx.More(); wx.Next()) {
		const TopoDS_Edge &e = wx.Current();
		double t0, t1;
		Handle(Geom2d_Curve) g = BRep_Tool::CurveOnSurface(e, f, t0, t1);
		std::string cw = who + " curve " + std::to_string(cv.size());
		if (g.IsNull())
			refuse(PX_E_PARSE, "%s: an edge has no curve on the "
			       "surface", cw.c_str());
		double tol = edge_tol(e);
		Handle(Geom2d_BSplineCurve) b = within_degree(
			Geom2dConvert::CurveToBSplineCurve(
				new Geom2d_TrimmedCurve(g, t0, t1)),
			std::min(gs.UResolution(tol), gs.VResolution(tol)));
		cv.push_back(curve_of<Geom2d_BSplineCurve, gp_Pnt2d>(c, b, 2, cw));
		clamp_to_surface(c, cv.back(), s, e, cw);
		rev.push_back(e.Orientation() == TopAbs_REVERSED ? 1 : 0);
		ce.push_back(px_brep_coedge{edge_of(c, m, e)});
		degen.push_back(BRep_Tool::Degenerated(e) ? 1 : 0);
	}
	close_poles(c, cv, rev, degen);
	if ((int)cv.size() != n_all || cv.empty())
		refuse(PX_E_PARSE, "%s: the wire is not one closed chain of "
		       "edges (%zu of %d edges connected)", who.c_str(),
		       cv.size(), n_all);
	px_trim_loop lp;
	lp.curves = cv.data();
	lp.n_curves = (int)cv.size();
	lp.reversed = rev.data();
	*coedges = ce.data();
	return lp;
}

// The face's loops (outer wire first), then the checks the distance
// model would refuse it for: a zero area, loops px_trim rejects.
void add_face(px_cad &c, model_src &m, const TopoDS_Face &f, int shell,
	      double size)
{
	int k = (int)c.faces.size();
	std::string who = face_name(m, f, k);
	px_brep_face_desc fd;
	fd.surf = surface_of(c, f, who);
	TopoDS_Wire outer = BRepTools::OuterWire(f);
	if (outer.IsNull())
		refuse(PX_E_PARSE, "%s has no outer wire", who.c_str());
	std::vector<TopoDS_Wire> wires(1, outer);
	for (TopExp_Explorer ex(f, TopAbs_WIRE); ex.More(); ex.Next())
		if (!ex.Current().IsSame(outer))
			wires.push_back(TopoDS::Wire(ex.Current()));
	c.loops.emplace_back();
	c.coedge_lists.emplace_back();
	std::vector<px_trim_loop> &lp = c.loops.back();
	std::vector<const px_brep_coedge *> &cl = c.coedge_lists.back();
	cl.resize(wires.size());
	for (size_t i = 0; i < wires.size(); i++)
		lp.push_back(loop_of(c, m, f, fd.surf, wires[i],
				     who + " loop " + std::to_string(i), &cl[i]));
	GProp_GProps props;
	BRepGProp::SurfaceProperties(f, props);
	if (!(std::fabs(props.Mass()) > 1e-12 * size * size))
		refuse(PX_E_DEGENERATE, "%s has zero area", who.c_str());
	px_trim_error te;
	px_trim *t = nullptr;
	int rc = px_trim_create(lp.data(), (int)lp.size(), nullptr, &te, &t);
	px_trim_free(t);
	if (rc != PX_OK)
		refuse(rc, "%s: %s", who.c_str(), te.msg);
	fd.loops = lp.data();
	fd.n_loops = (int)lp.size();
	fd.coedges = cl.data();
	fd.reversed = f.Orientation() == TopAbs_REVERSED ? 1 : 0;
	fd.shell = shell;
	fd.id = shape_id(m, f);
	c.faces.push_back(fd);
}

// Closed: every non-degenerate edge used once forwards and once
// backwards by the shell's faces (a seam counts both within its face).
bool shell_closed(const TopoDS_Shape &sh)
{
	TopTools_IndexedMapOfShape em;
	std::vector<int> fw, bw;
	int n = 0;
	for (TopExp_Explorer ex(sh, TopAbs_EDGE); ex.More(); ex.Next()) {
		const TopoDS_Edge &e = TopoDS::Edge(ex.Current());
		if (BRep_Tool::Degenerated(e))
			continue;
		int i = em.Add(e) - 1;
		if ((size_t)i >= fw.size())
			fw.push_back(0), bw.push_back(0);
		if (e.Orientation() == TopAbs_FORWARD)
			fw[(size_t)i]++;
		else if (e.Orientation() == TopAbs_REVERSED)
			bw[(size_t)i]++;
		else
			return false;
		n++;
	}
	for (size_t i = 0; i < fw.size(); i++)
		if (fw[i] != 1 || bw[i] != 1)
			return false;
	return n > 0;
}

void add_shell(px_cad &c, model_src &m, const TopoDS_Shape &sh, int solid,
	       bool closed, double size)
{
	int s = (int)c.shells.size();
	c.shells.push_back(px_brep_shell_desc{closed ? 1 : 0, solid, 0});
	for (TopExp_Explorer ex(sh, TopAbs_FACE); ex.More(); ex.Next())
		add_face(c, m, TopoDS::Face(ex.Current()), s, size);
}

// Solids (outer shell first), then, for the whole file, free shells
// and free faces (one open shell of them).
void collect(px_cad &c, model_src &m, int want)
{
	double size = 0;
	for (int i = 1; i <= m.vertex_map.Extent(); i++) {
		gp_Pnt p = BRep_Tool::Pnt(TopoDS::Vertex(m.vertex_map(i)));
		c.vertices.push_back(px_v3(p.X(), p.Y(), p.Z()));
		size = std::max(size, std::fabs(p.X()) + std::fabs(p.Y()) +
					      std::fabs(p.Z()));
	}
	size = std::max(size, 1e-300);
	int k = 0;
	for (TopExp_Explorer ex(m.shape, TopAbs_SOLID); ex.More();
	     ex.Next(), k++) {
		if (want >= 0 && k != want)
			continue;
		const TopoDS_Solid &so = TopoDS::Solid(ex.Current());
		TopoDS_Shell outer = BRepClass3d::OuterShell(so);
		int id = c.desc.n_solids++;
		if (!outer.IsNull())
			add_shell(c, m, outer, id, shell_closed(outer), size);
		for (TopExp_Explorer sx(so, TopAbs_SHELL); sx.More(); sx.Next())
			if (!sx.Current().IsSame(outer))
				add_shell(c, m, sx.Current(), id,
					  shell_closed(sx.Current()), size);
	}
	c.n_solids_file = k;
	if (want >= k)
		refuse(PX_E_INVAL, "solid %d asked, the file has %d", want, k);
	if (want >= 0)
		return;
	for (TopExp_Explorer ex(m.shape, TopAbs_SHELL, TopAbs_SOLID);
	     ex.More(); ex.Next())
		add_shell(c, m, ex.Current(), -1, shell_closed(ex.Current()),
			  size);
	TopoDS_Compound free_faces;
	BRep_Builder bb;
	bb.MakeCompound(free_faces);
	int nf = 0;
	for (TopExp_Explorer ex(m.shape, TopAbs_FACE, TopAbs_SHELL); ex.More();
	     ex.Next(), nf++)
		bb.Add(free_faces, ex.Current());
	if (nf)
		add_shell(c, m, free_faces, -1, false, size);
}

void fill_desc(px_cad &c, const std::string &path, double scale)
{
	px_brep_desc &d = c.desc;
	if (c.faces.empty())
		refuse(PX_E_PARSE, "no face in the file");
	d.faces = c.faces.data();
	d.n_faces = (int)c.faces.size();
	d.edges = c.edges.data();
	d.n_edges = (int)c.edges.size();
	d.vertices = c.vertices.data();
	d.n_vertices = (int)c.vertices.size();
	d.shells = c.shells.data();
	d.n_shells = (int)c.shells.size();
	d.scale = 0.001 * scale;
	size_t slash = path.find_last_of('/');
	c.name = slash == std::string::npos ? path : path.substr(slash + 1);
	c.source = path;
	d.name = c.name.c_str();
	d.source = c.source.c_str();
}

void load(px_cad &c, const std::string &path, const px_cad_opts &o)
{
	check_file(path, o.max_bytes ? o.max_bytes : PX_CAD_MAX_BYTES);
	read_result rr;
	read_file(path, rr);
	model_src m;
	convert(rr, m);
	collect(c, m, o.solid);
	fill_desc(c, path, o.scale);
}

void say(char *msg, size_t len, const char *path, const std::string &what)
{
	if (msg && len)
		snprintf(msg, len, "%s: %s", path, what.c_str());
}

} // namespace

extern "C" int px_cad_load(const char *path, const struct px_cad_opts *opts,
			   struct px_cad **out, char *msg, size_t msg_len)
{
	if (msg && msg_len)
		msg[0] = 0;
	if (out)
		*out = nullptr;
	px_cad_opts o;
	px_cad_opts_default(&o);
	if (opts)
		o = *opts;
	if (!path || !out || !std::isfinite(o.scale) || !(o.scale > 0) ||
	    o.solid < -1) {
		say(msg, msg_len, path ? path : "<null>",
		    "invalid arguments (path, output, scale > 0, solid >= -1)");
		return PX_E_INVAL;
	}
	px_cad *c = nullptr;
	try {
		std::lock_guard<std::mutex> g(load_lock);
		c = new px_cad();
		std::memset(&c->desc, 0, sizeof c->desc);
		load(*c, path, o);
		*out = c;
		return PX_OK;
	} catch (const refusal &r) {
		say(msg, msg_len, path, r.what);
		delete c;
		return r.code;
	} catch (const Standard_Failure &e) {
		say(msg, msg_len, path,
		    std::string("OpenCASCADE failed: ") + e.DynamicType()->Name() +
			    (e.GetMessageString() && *e.GetMessageString()
				     ? std::string(": ") + e.GetMessageString()
				     : std::string()));
		delete c;
		return PX_E_PARSE;
	} catch (const std::bad_alloc &) {
		say(msg, msg_len, path, "out of memory");
		delete c;
		return PX_E_NOMEM;
	} catch (const std::exception &e) {
		say(msg, msg_len, path, std::string("import failed: ") + e.what());
		delete c;
		return PX_E_PARSE;
	} catch (...) {
		say(msg, msg_len, path, "import failed (unknown exception)");
		delete c;
		return PX_E_PARSE;
	}
}

extern "C" const struct px_brep_desc *px_cad_desc(const struct px_cad *c)
{
	return c ? &c->desc : nullptr;
}

extern "C" int px_cad_solid_count(const struct px_cad *c)
{
	return c ? c->n_solids_file : 0;
}

extern "C" void px_cad_free(struct px_cad *c)
{
	delete c;
}
