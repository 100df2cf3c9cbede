/*
 * libFuzzer target: candump -l log reading (devices/px_can.h): every
 * line through px_can_log_parse(), and the whole input as a file through
 * px_can_replay_open() and the replay bus.
 * Invariants: a parsed frame has a length its kind allows and formats
 * back (px_can_log_format) into a line that parses to the same frame,
 * interface and time; the replay bus opens or names the file and line,
 * delivers at most as many frames as the file has lines, never before
 * their time, and drains in bounded calls.
 */
#include "fuzz_util.h"

#include "px_can.h"

static void same(const struct px_can_msg *a, const struct px_can_msg *b)
{
	if (a->f.can_id != b->f.can_id || a->f.len != b->f.len ||
	    a->fd != b->fd || (a->fd && a->f.flags != b->f.flags))
		abort();
	if (!(a->f.can_id & CAN_RTR_FLAG) &&
	    memcmp(a->f.data, b->f.data, a->f.len) != 0)
		abort();
}

static void one_line(const char *line)
{
	struct px_can_msg m, m2;
	int64_t t = -1, t2 = -1;
	char ifn[32], ifn2[32], out[400], tiny[8];
	int rc = px_can_log_parse(line, &m, &t, ifn, sizeof ifn);
	if (rc != PX_OK) {
		if (rc != PX_E_PARSE)
			abort();
		return;
	}
	if (t < 0)
		abort();
	if (m.fd ? m.f.len > CANFD_MAX_DLEN : m.f.len > CAN_MAX_DLEN)
		abort();
	rc = px_can_log_format(&m, t, ifn, out, sizeof out);
	if (rc <= 0 || (size_t)rc >= sizeof out)
		abort();
	if (px_can_log_parse(out, &m2, &t2, ifn2, sizeof ifn2) != PX_OK)
		abort();
	same(&m, &m2);
	if (t2 != t || strcmp(ifn, ifn2) != 0)
		abort();
	if (px_can_log_format(&m, t, ifn, tiny, sizeof tiny) != PX_E_NOSPC)
		abort();
	/* no interface buffer, no time */
	if (px_can_log_parse(line, &m2, NULL, NULL, 0) != PX_OK)
		abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char *s = malloc(size + 1), *p, *nl;
	struct px_can_bus *b = NULL;
	char msg[256];
	size_t lines = 1, i;
	int rc;

	if (!s)
		abort();
	memcpy(s, data, size);
	s[size] = '\0';
	for (i = 0; i < size; i++)
		if (s[i] == '\n')
			lines++;
	/* line by line, as a string without its newline */
	for (p = s; p && *p; p = nl ? nl + 1 : NULL) {
		nl = strchr(p, '\n');
		if (nl)
			*nl = '\0';
		one_line(p);
	}
	free(s);

	/* the file */
	rc = px_can_replay_open(fz_file(".log", data, size), NULL, &b, msg,
				sizeof msg);
	if (rc != PX_OK) {
		if (b || rc != PX_E_PARSE)
			abort();
		fz_check_msg(msg, sizeof msg);
		return 0;
	}
	{
		struct px_can_msg m;
		int64_t now = 1000;
		size_t got = 0, calls = 0;
		/* a replay bus must drain: at most every line, in order */
		while (calls++ < 4 * lines + 64) {
			rc = px_can_bus_recv(b, now, &m);
			if (rc == PX_OK) {
				/* never before its time; a file whose times go
				 * back delivers those frames at once */
				if (m.t_ns > now)
					abort();
				if (++got > lines)
					abort();
				continue;
			}
			if (rc != PX_E_AGAIN)
				abort();
			if (now > INT64_MAX / 4)
				break;
			now = now * 4; /* jump ahead, reach late frames */
		}
		{
			struct px_can_bus_stats st;
			px_can_bus_stats(b, &st);
			if (st.rx != got)
				abort();
		}
	}
	px_can_bus_close(b);
	return 0;
}
