#include "px_arena.h"

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

int px_arena_init(struct px_arena *a, void *buf, size_t cap)
{
	if (!a || (!buf && cap))
		return PX_E_INVAL;
	memset(a, 0, sizeof(*a));
	a->base_ = buf;
	a->cap_ = cap;
	return PX_OK;
}

int px_arena_init_alloc(struct px_arena *a, size_t cap)
{
	void *p;

	if (!a)
		return PX_E_INVAL;
	memset(a, 0, sizeof(*a));
	if (cap == 0)
		return PX_OK;
	/* Fresh pages are mapped lazily; the memset faults them all in now
	 * so that a cycle never takes a page fault on arena memory. */
	if (posix_memalign(&p, PX_ARENA_ALIGN, cap) != 0)
		return PX_E_NOMEM;
	memset(p, 0, cap);
	a->base_ = p;
	a->cap_ = cap;
	a->owned_ = 1;
	return PX_OK;
}

void px_arena_fini(struct px_arena *a)
{
	if (!a)
		return;
	if (a->owned_)
		free(a->base_);
	memset(a, 0, sizeof(*a));
}

void *px_arena_alloc(struct px_arena *a, size_t size, size_t align)
{
	uintptr_t start, aligned;
	size_t pad;

	if (!a)
		return NULL;
	if (align == 0)
		align = PX_ARENA_ALIGN;
	if (align & (align - 1))
		return NULL;
	/* Align the address, not the offset: a caller buffer need not be
	 * aligned itself. */
	start = (uintptr_t)a->base_ + a->used_;
	aligned = (start + (align - 1)) & ~(uintptr_t)(align - 1);
	pad = (size_t)(aligned - start);
	if (!a->base_ || pad > a->cap_ - a->used_ ||
	    size > a->cap_ - a->used_ - pad) {
		a->failed_++;
		return NULL;
	}
	a->used_ += pad + size;
	if (a->used_ > a->high_water_)
		a->high_water_ = a->used_;
	return (void *)aligned;
}

void *px_arena_calloc(struct px_arena *a, size_t n, size_t elem_size,
		      size_t align)
{
	void *p;

	if (elem_size && n > SIZE_MAX / elem_size) {
		if (a)
			a->failed_++;
		return NULL;
	}
	p = px_arena_alloc(a, n * elem_size, align);
	if (p && n * elem_size != 0)
		memset(p, 0, n * elem_size);
	return p;
}

size_t px_arena_mark(const struct px_arena *a)
{
	return a ? a->used_ : 0;
}

void px_arena_reset_to(struct px_arena *a, size_t mark)
{
	if (a && mark <= a->used_)
		a->used_ = mark;
}

size_t px_arena_used(const struct px_arena *a)
{
	return a ? a->used_ : 0;
}

size_t px_arena_high_water(const struct px_arena *a)
{
	return a ? a->high_water_ : 0;
}

size_t px_arena_capacity(const struct px_arena *a)
{
	return a ? a->cap_ : 0;
}

size_t px_arena_failed(const struct px_arena *a)
{
	return a ? a->failed_ : 0;
}
