// proxima-cadgen: writes the test parts of the CAD importer as STEP and
// IGES files, modelled with OpenCASCADE, in millimetres.
//
//   proxima-cadgen [--unit MM|M] [--format step|iges|both] DIR [PART...]
//
// Parts (all when none is named):
//   filleted_block  60 x 40 x 20 block, every edge filleted (r 3), a
//                   drilled hole (d 12) through it
//   plate           100 x 60 x 8 plate with four holes and a pocket
//   bottle          a bottle-like solid (body, filleted shoulder and
//                   neck) shelled to 1 mm walls, open at the neck
//   sheet           a free-form B-spline sheet trimmed by a spline loop,
//                   with a circular hole
//   cylsphere       a cylinder and a sphere fused (seams and a pole)
//   assembly        filleted_block and cylsphere side by side: two
//                   solids in one file
//   crossed_sheet   the sheet with a hole that crosses its outer loop
//                   (a faulty part: readers must refuse it)
// --unit gives the unit written to the file (the geometry is the same);
// IGES files hold the B-rep (shells and solids), not loose faces.
// Exit status 0 when every file was written, 1 otherwise.
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <BRepAlgoAPI_Cut.hxx>
#include <BRepAlgoAPI_Fuse.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <BRep_Builder.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Trsf.hxx>
#include <BRepFilletAPI_MakeFillet.hxx>
#include <BRepLib.hxx>
#include <BRepOffsetAPI_MakeThickSolid.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepPrimAPI_MakeCylinder.hxx>
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRep_Tool.hxx>
#include <Geom2dAPI_Interpolate.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_Circle.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_Plane.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Writer.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <STEPControl_Writer.hxx>
#include <ShapeFix_Face.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TColgp_HArray1OfPnt2d.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <gp_Ax2.hxx>
#include <gp_Ax2d.hxx>
#include <gp_Pln.hxx>

namespace {

TopoDS_Shape filleted_block()
{
	TopoDS_Shape box = BRepPrimAPI_MakeBox(60, 40, 20).Shape();
	BRepFilletAPI_MakeFillet fil(box);
	for (TopExp_Explorer ex(box, TopAbs_EDGE); ex.More(); ex.Next())
		fil.Add(3.0, TopoDS::Edge(ex.Current()));
	TopoDS_Shape rounded = fil.Shape();
	TopoDS_Shape drill = BRepPrimAPI_MakeCylinder(
		gp_Ax2(gp_Pnt(30, 20, -5), gp_Dir(0, 0, 1)), 6, 30).Shape();
	return BRepAlgoAPI_Cut(rounded, drill).Shape();
}

TopoDS_Shape plate()
{
	TopoDS_Shape s = BRepPrimAPI_MakeBox(100, 60, 8).Shape();
	const double hx[4] = {10, 90, 10, 90}, hy[4] = {10, 10, 50, 50};
	for (int i = 0; i < 4; i++) {
		TopoDS_Shape h = BRepPrimAPI_MakeCylinder(
			gp_Ax2(gp_Pnt(hx[i], hy[i], -1), gp_Dir(0, 0, 1)), 4,
			10).Shape();
		s = BRepAlgoAPI_Cut(s, h).Shape();
	}
	TopoDS_Shape pocket =
		BRepPrimAPI_MakeBox(gp_Pnt(30, 20, 4), 40, 20, 5).Shape();
	return BRepAlgoAPI_Cut(s, pocket).Shape();
}

// The face of shape with the highest centre along z (the neck's top).
TopoDS_Face top_face(const TopoDS_Shape &s)
{
	TopoDS_Face best;
	double zb = -1e300;
	for (TopExp_Explorer ex(s, TopAbs_FACE); ex.More(); ex.Next()) {
		TopoDS_Face f = TopoDS::Face(ex.Current());
		Handle(Geom_Plane) pl =
			Handle(Geom_Plane)::DownCast(BRep_Tool::Surface(f));
		if (pl.IsNull())
			continue;
		double z = pl->Location().Z();
		if (z > zb)
			zb = z, best = f;
	}
	return best;
}

TopoDS_Shape bottle()
{
	TopoDS_Shape body = BRepPrimAPI_MakeCylinder(
		gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 20, 60).Shape();
	BRepFilletAPI_MakeFillet fb(body);
	for (TopExp_Explorer ex(body, TopAbs_EDGE); ex.More(); ex.Next())
		if (!BRep_Tool::Degenerated(TopoDS::Edge(ex.Current())))
			fb.Add(5.0, TopoDS::Edge(ex.Current()));
	TopoDS_Shape neck = BRepPrimAPI_MakeCylinder(
		gp_Ax2(gp_Pnt(0, 0, 59), gp_Dir(0, 0, 1)), 8, 16).Shape();
	TopoDS_Shape s = BRepAlgoAPI_Fuse(fb.Shape(), neck).Shape();
	TopTools_ListOfShape open;
	open.Append(top_face(s));
	BRepOffsetAPI_MakeThickSolid thick;
	thick.MakeThickSolidByJoin(s, open, -1.0, 1e-4);
	return thick.Shape();
}

// A wavy bicubic sheet over 80 x 60, cut by a closed spline loop in its
// parameter plane and a circular hole of radius hole_r (parameter
// units; the loop is 0.29 to 0.43 from the middle).
TopoDS_Shape trimmed_sheet(double hole_r)
{
	TColgp_Array2OfPnt poles(1, 5, 1, 4);
	for (int i = 1; i <= 5; i++)
		for (int j = 1; j <= 4; j++) {
			double x = 20.0 * (i - 1), y = 20.0 * (j - 1);
			double z = 6.0 * ((i + j) % 3 - 1) + 2.0 * (i == 3);
			poles(i, j) = gp_Pnt(x, y, z);
		}
	TColStd_Array1OfReal ku(1, 3), kv(1, 2);
	TColStd_Array1OfInteger mu(1, 3), mv(1, 2);
	ku(1) = 0, ku(2) = 0.5, ku(3) = 1, mu(1) = 4, mu(2) = 1, mu(3) = 4;
	kv(1) = 0, kv(2) = 1, mv(1) = 4, mv(2) = 4;
	Handle(Geom_BSplineSurface) surf =
		new Geom_BSplineSurface(poles, ku, kv, mu, mv, 3, 3);
	const int n = 7;
	Handle(TColgp_HArray1OfPnt2d) pts = new TColgp_HArray1OfPnt2d(1, n);
	for (int i = 0; i < n; i++) {
		double a = 2 * M_PI * i / n, r = 0.36 + 0.07 * ((i % 2) ? 1 : -1);
		pts->SetValue(i + 1, gp_Pnt2d(0.5 + r * cos(a), 0.5 + 0.9 * r * sin(a)));
	}
	Geom2dAPI_Interpolate ip(pts, Standard_True, 1e-9);
	ip.Perform();
	Handle(Geom2d_BSplineCurve) loop = ip.Curve();
	TopoDS_Edge eo = BRepBuilderAPI_MakeEdge(loop, surf).Edge();
	TopoDS_Wire wo = BRepBuilderAPI_MakeWire(eo).Wire();
	Handle(Geom2d_Circle) circ =
		new Geom2d_Circle(gp_Ax2d(gp_Pnt2d(0.55, 0.5), gp_Dir2d(1, 0)), hole_r);
	TopoDS_Edge eh = BRepBuilderAPI_MakeEdge(circ, surf).Edge();
	TopoDS_Wire wh = BRepBuilderAPI_MakeWire(eh).Wire();
	BRepBuilderAPI_MakeFace mf(surf, wo, Standard_True);
	mf.Add(TopoDS::Wire(wh.Reversed()));
	TopoDS_Face f = mf.Face();
	BRepLib::BuildCurves3d(f);
	ShapeFix_Face fix(f);
	fix.FixOrientation();
	fix.Perform();
	return fix.Face();
}

TopoDS_Shape sheet()
{
	return trimmed_sheet(0.1);
}

// A faulty part for the importer's refusals: the hole crosses the
// sheet's outer loop.
TopoDS_Shape crossed_sheet()
{
	return trimmed_sheet(0.35);
}

TopoDS_Shape cylsphere()
{
	TopoDS_Shape cyl = BRepPrimAPI_MakeCylinder(
		gp_Ax2(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), 10, 40).Shape();
	TopoDS_Shape sph =
		BRepPrimAPI_MakeSphere(gp_Pnt(0, 0, 40), 15).Shape();
	return BRepAlgoAPI_Fuse(cyl, sph).Shape();
}

// Two solids in one file: the block and, beside it, the fused
// cylinder and sphere.
TopoDS_Shape assembly()
{
	TopoDS_Compound c;
	BRep_Builder b;
	gp_Trsf move;
	move.SetTranslation(gp_Vec(100, 0, 0));
	b.MakeCompound(c);
	b.Add(c, filleted_block());
	b.Add(c, BRepBuilderAPI_Transform(cylsphere(), move, Standard_True).Shape());
	return c;
}

struct part {
	const char *name;
	TopoDS_Shape (*make)();
};

const part parts[] = {
	{"filleted_block", filleted_block}, {"plate", plate},
	{"bottle", bottle}, {"sheet", sheet}, {"cylsphere", cylsphere},
	{"assembly", assembly}, {"crossed_sheet", crossed_sheet},
};

// The shape with its coordinates in unit (modelled in millimetres).
TopoDS_Shape in_unit(const TopoDS_Shape &s, const char *unit)
{
	if (strcmp(unit, "M"))
		return s;
	gp_Trsf t;
	t.SetScale(gp_Pnt(0, 0, 0), 0.001);
	return BRepBuilderAPI_Transform(s, t, Standard_True).Shape();
}

// The STEP writer labels the file with write.step.unit but writes the
// coordinates as given: they are converted first.
bool write_step(const TopoDS_Shape &shape, const std::string &path,
		const char *unit)
{
	TopoDS_Shape s = in_unit(shape, unit);
	STEPControl_Writer w;
	Interface_Static::SetCVal("xstep.cascade.unit", "MM");
	Interface_Static::SetCVal("write.step.unit", unit);
	if (w.Transfer(s, STEPControl_AsIs) != IFSelect_RetDone)
		return false;
	return w.Write(path.c_str()) == IFSelect_RetDone;
}

bool write_iges(const TopoDS_Shape &s, const std::string &path,
		const char *unit)
{
	IGESControl_Controller::Init();
	Interface_Static::SetCVal("xstep.cascade.unit", "MM");
	Interface_Static::SetCVal("write.iges.unit", unit);
	IGESControl_Writer w(unit, 1);
	if (!w.AddShape(s))
		return false;
	w.ComputeModel();
	return w.Write(path.c_str());
}

int usage()
{
	fprintf(stderr, "usage: proxima-cadgen [--unit MM|M] "
			"[--format step|iges|both] DIR [PART...]\nparts:");
	for (const part &p : parts)
		fprintf(stderr, " %s", p.name);
	fprintf(stderr, "\n");
	return 2;
}

// Builds and writes one part; says what failed.
bool make_part(const part &p, const std::string &dir, const char *unit,
	       bool step, bool iges)
{
	try {
		TopoDS_Shape s = p.make();
		if (s.IsNull()) {
			fprintf(stderr, "proxima-cadgen: %s: modelling failed\n",
				p.name);
			return false;
		}
		std::string base = dir + "/" + p.name;
		bool ok = true;
		if (step && !write_step(s, base + ".step", unit))
			ok = false, fprintf(stderr, "proxima-cadgen: %s.step: "
					    "write failed\n", base.c_str());
		if (iges && !write_iges(s, base + ".iges", unit))
			ok = false, fprintf(stderr, "proxima-cadgen: %s.iges: "
					    "write failed\n", base.c_str());
		return ok;
	} catch (const Standard_Failure &e) {
		fprintf(stderr, "proxima-cadgen: %s: %s: %s\n", p.name,
			e.DynamicType()->Name(), e.GetMessageString());
		return false;
	}
}

} // namespace

int main(int argc, char **argv)
{
	const char *unit = "MM", *fmt = "both";
	int i = 1;
	for (; i < argc && argv[i][0] == '-'; i++) {
		if (!strcmp(argv[i], "--unit") && i + 1 < argc)
			unit = argv[++i];
		else if (!strcmp(argv[i], "--format") && i + 1 < argc)
			fmt = argv[++i];
		else
			return usage();
	}
	if (i >= argc || (strcmp(unit, "MM") && strcmp(unit, "M")) ||
	    (strcmp(fmt, "step") && strcmp(fmt, "iges") && strcmp(fmt, "both")))
		return usage();
	std::string dir = argv[i++];
	bool step = strcmp(fmt, "iges") != 0, iges = strcmp(fmt, "step") != 0;
	// The writers report progress on the console; the tool reports
	// only failures.
	Message::DefaultMessenger()->ChangePrinters().Clear();
	bool ok = true;
	int made = 0;
	for (const part &p : parts) {
		bool want = i >= argc;
		for (int k = i; k < argc; k++)
			want = want || !strcmp(argv[k], p.name);
		if (!want)
			continue;
		ok = make_part(p, dir, unit, step, iges) && ok;
		made++;
	}
	if (!made)
		return usage();
	return ok ? 0 : 1;
}
