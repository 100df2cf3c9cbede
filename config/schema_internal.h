/*
 * schema_internal.h - private to the library: the macros that write the
 * key tables (struct px_config_key) of the config, control and scene
 * schemas, so the three sections declare keys the same way.
 *
 * Each K_* expands to one designated initializer of a key of field f of
 * struct T under the YAML name nm; fields not named stay 0. A number key
 * is always range-checked [lo, hi] (fl may add PX_CONFIG_MIN_EXCL etc.).
 * Setup-time data only: nothing here runs in a cycle.
 */
#ifndef PX_CONFIG_SCHEMA_INTERNAL_H
#define PX_CONFIG_SCHEMA_INTERNAL_H

#include <stddef.h>

#include "px_config.h"

#define RANGE (PX_CONFIG_HAS_MIN | PX_CONFIG_HAS_MAX)

#define K_INT(T, f, nm, fl, lo, hi, def)                                    \
	{.name = nm, .type = PX_CONFIG_T_INT64, .offset = offsetof(T, f),     \
	 .flags = (fl) | RANGE, .imin = (lo), .imax = (hi), .idef = (def)}
#define K_INTP(T, f, nm, fl, lo, hi, def, pres)                             \
	{.name = nm, .type = PX_CONFIG_T_INT64, .offset = offsetof(T, f),     \
	 .flags = (fl) | RANGE | PX_CONFIG_PRESENT, .imin = (lo), .imax = (hi), \
	 .idef = (def), .present_offset = offsetof(T, pres)}
#define K_DUR(T, f, nm, fl, lo, hi, def)                                    \
	{.name = nm, .type = PX_CONFIG_T_DURATION, .offset = offsetof(T, f),  \
	 .flags = (fl) | RANGE, .imin = (lo), .imax = (hi), .idef = (def)}
#define K_DBL(T, f, nm, fl, lo, hi, def)                                    \
	{.name = nm, .type = PX_CONFIG_T_DOUBLE, .offset = offsetof(T, f),    \
	 .flags = (fl) | RANGE, .dmin = (lo), .dmax = (hi), .ddef = (def)}
/* Optional number whose absence is recorded in field pres; the reader
 * still stores def, which must lie in the range. */
#define K_DBLPD(T, f, nm, fl, lo, hi, def, pres)                            \
	{.name = nm, .type = PX_CONFIG_T_DOUBLE, .offset = offsetof(T, f),    \
	 .flags = (fl) | RANGE | PX_CONFIG_PRESENT, .dmin = (lo), .dmax = (hi), \
	 .ddef = (def), .present_offset = offsetof(T, pres)}
/* The same where absence means "take it from elsewhere": the
 * placeholder default hi only has to lie in the range. */
#define K_DBLP(T, f, nm, fl, lo, hi, pres)                                  \
	K_DBLPD(T, f, nm, fl, lo, hi, hi, pres)
/* Three numbers (a vector), default 0. */
#define K_VEC(T, f, nm, fl, lo, hi)                                         \
	{.name = nm, .type = PX_CONFIG_T_DOUBLE, .offset = offsetof(T, f),    \
	 .flags = (fl) | RANGE, .dmin = (lo), .dmax = (hi), .fixed_count = 3}
/* Optional vector, as K_DBLPD and K_DBLP. */
#define K_VECPD(T, f, nm, fl, lo, hi, def, pres)                            \
	{.name = nm, .type = PX_CONFIG_T_DOUBLE, .offset = offsetof(T, f),    \
	 .flags = (fl) | RANGE | PX_CONFIG_PRESENT, .dmin = (lo), .dmax = (hi), \
	 .fixed_count = 3, .ddef = (def), .present_offset = offsetof(T, pres)}
#define K_VECP(T, f, nm, fl, lo, hi, pres)                                  \
	K_VECPD(T, f, nm, fl, lo, hi, hi, pres)
#define K_BOOL(T, f, nm, def)                                               \
	{.name = nm, .type = PX_CONFIG_T_BOOL, .offset = offsetof(T, f),      \
	 .idef = (def)}
#define K_STR(T, f, nm, fl)                                                 \
	{.name = nm, .type = PX_CONFIG_T_STRING, .offset = offsetof(T, f),    \
	 .flags = (fl) | PX_CONFIG_NONEMPTY}
#define K_ENUM(T, f, nm, fl, nms, def)                                      \
	{.name = nm, .type = PX_CONFIG_T_ENUM, .offset = offsetof(T, f),      \
	 .flags = (fl), .names = (nms), .idef = (def)}
#define K_SUB(T, f, nm, sch)                                                \
	{.name = nm, .type = PX_CONFIG_T_SUB, .offset = offsetof(T, f),       \
	 .sub = &(sch)}
#define K_SUBP(T, f, nm, sch, pres)                                         \
	{.name = nm, .type = PX_CONFIG_T_SUB, .offset = offsetof(T, f),       \
	 .sub = &(sch), .flags = PX_CONFIG_PRESENT,                           \
	 .present_offset = offsetof(T, pres)}
/* Sequence of lo..hi sub-documents of type ET; their count in cnt. */
#define K_SEQ(T, f, cnt, nm, fl, sch, ET, lo, hi)                           \
	{.name = nm, .type = PX_CONFIG_T_SEQ, .offset = offsetof(T, f),       \
	 .flags = (fl), .sub = &(sch), .elem = PX_CONFIG_T_SUB,               \
	 .elem_size = sizeof(ET), .count_offset = offsetof(T, cnt),           \
	 .min_count = (lo), .max_count = (hi)}
#define K_MAP(T, f, nm)                                                     \
	{.name = nm, .type = PX_CONFIG_T_MAP, .offset = offsetof(T, f)}

/* A schema var named nm over the key array keys, with cross-key check
 * chk (or NULL). */
#define SCHEMA(var, nm, keys, chk)                                          \
	static const struct px_config_schema var = {                        \
		nm, keys, sizeof(keys) / sizeof(keys[0]), chk}

/* What breaks ROS 2's name rules in s (tokens of [A-Za-z0-9_] split by
 * single '/', none starting with a digit, no leading or trailing '/',
 * shorter than max bytes), or NULL: for namespaces and topic names. */
const char *px__ros_name_problem(const char *s, size_t max);

#endif
