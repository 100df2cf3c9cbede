#include "px_param.h"

#include <stdatomic.h>
#include <string.h>

/* state: index (0..2) of the middle buffer, plus FRESH when the writer
 * has published it since the reader last took it. */
#define FRESH 4u
#define IDX 3u

struct px_param {
	_Alignas(64) _Atomic unsigned state;
	_Atomic uint64_t writes;
	_Alignas(64) unsigned back;  /* writer's */
	_Alignas(64) unsigned front; /* reader's */
	size_t size;
	unsigned char *buf[3];
};

size_t px_param_size(size_t size)
{
	return sizeof(struct px_param) + 3 * (size + 64) + 64;
}

int px_param_create(struct px_arena *a, size_t size, const void *init,
		    struct px_param **out)
{
	struct px_param *p;
	int i;

	if (!out)
		return PX_E_INVAL;
	*out = NULL;
	if (!a || size == 0 || size > SIZE_MAX / 4)
		return PX_E_INVAL;
	p = px_arena_alloc(a, sizeof(*p), 64);
	if (!p)
		return PX_E_NOSPC;
	for (i = 0; i < 3; i++) {
		/* Separate cache lines: the writer fills one while the
		 * reader reads another. */
		p->buf[i] = px_arena_alloc(a, size, 64);
		if (!p->buf[i])
			return PX_E_NOSPC;
		if (init)
			memcpy(p->buf[i], init, size);
		else
			memset(p->buf[i], 0, size);
	}
	p->size = size;
	p->front = 0;
	p->back = 1;
	atomic_init(&p->state, 2u);
	atomic_init(&p->writes, 0);
	*out = p;
	return PX_OK;
}

int px_param_write(struct px_param *p, const void *src)
{
	unsigned old;

	if (!p || !src)
		return PX_E_INVAL;
	memcpy(p->buf[p->back], src, p->size);
	/* Release: the copy above happens-before the reader's acquire of
	 * this index. */
	old = atomic_exchange_explicit(&p->state, p->back | FRESH,
				       memory_order_acq_rel);
	p->back = old & IDX;
	atomic_fetch_add_explicit(&p->writes, 1, memory_order_relaxed);
	return PX_OK;
}

const void *px_param_read(struct px_param *p, int *fresh)
{
	int got = 0;

	if (!p) {
		if (fresh)
			*fresh = 0;
		return NULL;
	}
	if (atomic_load_explicit(&p->state, memory_order_relaxed) & FRESH) {
		unsigned old = atomic_exchange_explicit(
			&p->state, p->front, memory_order_acq_rel);
		p->front = old & IDX;
		got = 1;
	}
	if (fresh)
		*fresh = got;
	return p->buf[p->front];
}

uint64_t px_param_writes(const struct px_param *p)
{
	return p ? atomic_load_explicit(&((struct px_param *)p)->writes,
					memory_order_relaxed)
		 : 0;
}
