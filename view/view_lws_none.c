/* The view of a build without libwebsockets: the JSON side works
 * (view_json.c), serving says what is missing. */
#include <stdio.h>

#include "px_view.h"

int px_view_create(const struct px_view_options *o, struct px_view **out,
		   char *msg, size_t cap)
{
	(void)o;
	if (out)
		*out = NULL;
	if (msg && cap)
		snprintf(msg, cap, "view: this build has no view server "
				   "(built without libwebsockets)");
	return PX_E_UNSUPPORTED;
}

int px_view_port(const struct px_view *v)
{
	(void)v;
	return PX_E_UNSUPPORTED;
}

int px_view_set_scene(struct px_view *v, const char *json, size_t len)
{
	(void)v, (void)json, (void)len;
	return PX_E_UNSUPPORTED;
}

int px_view_set_track(struct px_view *v, const char *json, size_t len)
{
	(void)v, (void)json, (void)len;
	return PX_E_UNSUPPORTED;
}

int px_view_set_sources(struct px_view *v, const struct px_view_sources *src)
{
	(void)v, (void)src;
	return PX_E_UNSUPPORTED;
}

int px_view_start(struct px_view *v)
{
	(void)v;
	return PX_E_UNSUPPORTED;
}

int px_view_feed_record(struct px_view *v, const struct px_app_record *r)
{
	(void)v, (void)r;
	return 0;
}

int px_view_feed_json(struct px_view *v, const char *json, size_t len)
{
	(void)v, (void)json, (void)len;
	return PX_E_UNSUPPORTED;
}

void px_view_end(struct px_view *v)
{
	(void)v;
}

void px_view_stats(struct px_view *v, struct px_view_stats *s)
{
	(void)v;
	if (s)
		*s = (struct px_view_stats){0};
}

void px_view_stop(struct px_view *v, int wait_ms)
{
	(void)v, (void)wait_ms;
}

void px_view_free(struct px_view *v)
{
	(void)v;
}
