"""Build the proxima Python package's extension module with cffi.

    python3 python/build_ext.py OUTDIR --include DIR... --libdir DIR --rpath DIR

API mode: cffi writes a C file that includes python/proxima/_pxpy.h and
the library's headers, and the C compiler checks every declaration below
against them, so the binding cannot drift from the library's structs
unnoticed (ABI mode would repeat their layouts here by hand). The
whole-array loops live in _pxpy.c, compiled into the same module, so a
batch of points costs one Python call. The module links libproxima.so
with an rpath to --rpath (the build tree, or the installed libdir).
"""

import argparse
import os
import shutil
import sys

import cffi

HERE = os.path.dirname(os.path.abspath(__file__))
PKG = os.path.join(HERE, "proxima")

CDEF = """
struct px_model;
struct px_model_stream;
struct px_scene;
struct px_scene_tracking;

int pxpy_load(const char *path, double cloud_radius_m, double scale,
              struct px_model **out, char *msg, size_t msg_cap);
int pxpy_mesh(const double *xyz, size_t n_vertices, const int64_t *tri,
              size_t n_triangles, struct px_model **out, char *msg,
              size_t msg_cap);
int pxpy_cloud(const double *xyz, size_t n, double radius_m,
               struct px_model **out, char *msg, size_t msg_cap);
int pxpy_prim(int type, double a, double b, double c, struct px_model **out,
              char *msg, size_t msg_cap);
int pxpy_nurbs(int n_curves, const int *c_deg, const int *c_n,
               const double *c_knots, const double *c_xyz, const double *c_w,
               int n_surfs, const int *s_deg, const int *s_n,
               const double *s_knots, const double *s_xyz, const double *s_w,
               struct px_model **out, char *msg, size_t msg_cap);
void pxpy_model_free(struct px_model *m);
int pxpy_model_kind(const struct px_model *m);
unsigned pxpy_model_caps(const struct px_model *m);
const char *pxpy_model_name(const struct px_model *m);
void pxpy_model_box(const struct px_model *m, int world, double *box6);
size_t pxpy_model_bytes(const struct px_model *m);
int pxpy_set_pose(struct px_model *m, const double *q4, const double *t3,
                  char *msg, size_t msg_cap);
void pxpy_get_pose(const struct px_model *m, double *q4, double *t3);

struct pxpy_out {
    double *distance;
    double *point;
    double *direction;
    double *u, *v;
    double *gap;
    int32_t *index;
    int32_t *sub;
    int32_t *feature;
    int8_t *inside;
    int8_t *certified;
    int8_t *found;
    int8_t *jumped;
    int32_t *model;
};

int pxpy_query(const struct px_model *m, const double *p, size_t n,
               double max_dist, unsigned flags, const struct pxpy_out *o,
               size_t *bad, char *msg, size_t msg_cap);
int pxpy_stream_create(const struct px_model *m, int verify_every,
                       int max_solves, int cold_switch,
                       struct px_model_stream **out, char *msg,
                       size_t msg_cap);
void pxpy_stream_free(struct px_model_stream *s);
int pxpy_stream_query(struct px_model_stream *s, const double *p, size_t n,
                      double max_dist, unsigned flags,
                      const struct pxpy_out *o, size_t *bad, char *msg,
                      size_t msg_cap);
void pxpy_stream_stats(const struct px_model_stream *s, uint64_t *st9);
int pxpy_pair(const struct px_model *a, const struct px_model *b, int starts,
              int max_iters, double *out9, double *normal3, int *ints6,
              char *msg, size_t msg_cap);
int pxpy_scene_create(size_t capacity, struct px_scene **out, char *msg,
                      size_t msg_cap);
void pxpy_scene_free(struct px_scene *s);
int pxpy_scene_add(struct px_scene *s, struct px_model *m, char *msg,
                   size_t msg_cap);
int pxpy_scene_update(struct px_scene *s);
int pxpy_scene_nearest(const struct px_scene *s, const double *p, size_t n,
                       double max_dist, const struct pxpy_out *o, size_t *bad,
                       char *msg, size_t msg_cap);
int pxpy_scene_tracking_create(const struct px_scene *s,
                               struct px_scene_tracking **out, char *msg,
                               size_t msg_cap);
void pxpy_scene_tracking_free(struct px_scene_tracking *t);
int pxpy_scene_nearest_tracked(const struct px_scene *s,
                               struct px_scene_tracking *t, const double *p,
                               size_t n, double max_dist,
                               const struct pxpy_out *o, size_t *bad,
                               char *msg, size_t msg_cap);
struct px_urdf_robot;
int pxpy_robot_load(const char *path, const char *base, const char *tip,
                    const char *package_paths, struct px_urdf_robot **out,
                    char *msg, size_t msg_cap);
void pxpy_robot_free(struct px_urdf_robot *r);
int pxpy_robot_dof(const struct px_urdf_robot *r);
const char *pxpy_robot_joint_name(const struct px_urdf_robot *r, int j);
int pxpy_robot_limits(const struct px_urdf_robot *r, int j, double *out3);
int pxpy_robot_body_count(const struct px_urdf_robot *r);
struct px_model *pxpy_robot_body(const struct px_urdf_robot *r, int i,
                                 const char **link, int *frame);
int pxpy_robot_set_q(struct px_urdf_robot *r, const double *q, double *frames,
                     char *msg, size_t msg_cap);
const char *pxpy_strerror(int code);
const char *pxpy_version(void);
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("outdir")
    ap.add_argument("--include", action="append", default=[])
    ap.add_argument("--libdir", required=True)
    ap.add_argument("--rpath", required=True)
    ap.add_argument("--cflags", default="")
    a = ap.parse_args()

    ffi = cffi.FFI()
    ffi.cdef(CDEF)
    with open(os.path.join(PKG, "_pxpy.c")) as f:
        src = f.read()
    ffi.set_source(
        "proxima._proxima",
        src,
        include_dirs=[PKG] + [os.path.abspath(d) for d in a.include],
        library_dirs=[os.path.abspath(a.libdir)],
        libraries=["proxima"],
        extra_compile_args=["-std=c11", "-D_GNU_SOURCE", "-O2"] + a.cflags.split(),
        extra_link_args=["-Wl,-rpath," + a.rpath],
    )
    out = os.path.abspath(a.outdir)
    tmp = os.path.join(out, ".cffi-build")
    os.makedirs(tmp, exist_ok=True)
    so = ffi.compile(tmpdir=tmp, verbose=False)
    pkg_out = os.path.join(out, "proxima")
    os.makedirs(pkg_out, exist_ok=True)
    shutil.copy(so, os.path.join(pkg_out, os.path.basename(so)))
    for name in sorted(os.listdir(PKG)):
        if name.endswith(".py"):
            shutil.copy(os.path.join(PKG, name), os.path.join(pkg_out, name))
    return 0


if __name__ == "__main__":
    sys.exit(main())
