/*
 * tool_view.h - what the tools that serve the browser view share
 * (proxima-run --view, proxima-view): the [ADDR:]PORT argument and the
 * folder of the built page.
 */
#ifndef TOOL_VIEW_H
#define TOOL_VIEW_H

#include <stddef.h>

/* The port the view is served on when none is given (make run too). */
#define TOOL_VIEW_PORT 8765

/* "[ADDR:]PORT" ("[::1]:PORT" for IPv6): addr gets ADDR ("" when none),
 * *port 1..65535. Returns 0, or -1 for anything else. */
int tool_view_parse(const char *spec, char *addr, size_t cap, int *port);

/* The built page's folder: build/view/web beside this program's
 * build/bin, else share/proxima/view beside an installed bin. */
void tool_view_root(char *buf, size_t cap);

/* "http://ADDR:PORT/" (127.0.0.1 for ""; [ADDR] for IPv6). */
void tool_view_url(const char *addr, int port, char *buf, size_t cap);

#endif
