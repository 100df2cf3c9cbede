/*
 * bridge_test.h - what the bridge's tests share (builds with Cyclone
 * DDS only): the monotonic clock, a participant configured as the
 * bridge configures its own, and the second process, the test binary
 * again with its role in an environment variable.
 */
#ifndef PX_BRIDGE_TEST_H
#define PX_BRIDGE_TEST_H

#include <signal.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <dds/dds.h>

#include "px_bridge.h"

static inline int64_t mono_ns(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (int64_t)ts.tv_sec * 1000000000 + ts.tv_nsec;
}

/* A participant of this process on the domain; *dom the domain entity
 * to delete after it (0: it existed). */
static inline dds_entity_t join(int domain, dds_entity_t *dom)
{
	struct px_bridge_config c;
	char xml[PX_BRIDGE_DDS_CONFIG_MAX];
	px_bridge_config_default(&c);
	c.domain_id = domain;
	if (px_bridge_dds_config(&c, xml, sizeof(xml)) != PX_OK)
		return -1;
	*dom = dds_create_domain((dds_domainid_t)domain, xml);
	return dds_create_participant((dds_domainid_t)domain, NULL, NULL);
}

/* This binary again, with env=role. */
static inline pid_t spawn_role(const char *env, const char *role)
{
	pid_t pid = fork();
	if (pid == 0) {
		char self[4096];
		ssize_t n = readlink("/proc/self/exe", self, sizeof(self) - 1);
		if (n > 0) {
			self[n] = '\0';
			setenv(env, role, 1);
			execl(self, self, (char *)NULL);
		}
		_exit(127);
	}
	return pid;
}

static inline void stop_child(pid_t pid)
{
	int st;
	if (pid <= 0)
		return;
	kill(pid, SIGTERM);
	waitpid(pid, &st, 0);
}

#endif
