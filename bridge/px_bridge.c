/* The bridge's config section, its topic naming and the Cyclone DDS
 * configuration it runs with: plain C, in every build (the DDS side is
 * px_bridge_dds.c, or px_bridge_dds_none.c without Cyclone DDS). */
#include <stdio.h>
#include <string.h>

#include "bridge_internal.h"
#include "schema_internal.h"

static const char *const discovery_names[] = {"auto", "unicast", "multicast",
					      NULL};

/* What each topic is called and carries (enum px_bridge_topic order). */
static const struct {
	const char *name, *type;
	int reliable;
} topics[PX_BRIDGE_TOPIC__COUNT] = {
	{"tool_pose", "geometry_msgs::msg::dds_::PoseStamped_", 0},
	{"proxy_pose", "geometry_msgs::msg::dds_::PoseStamped_", 0},
	{"wrench", "geometry_msgs::msg::dds_::WrenchStamped_", 0},
	{"closest_point", "geometry_msgs::msg::dds_::PointStamped_", 0},
	{"distance", "proxima_msgs::msg::dds_::Distance_", 0},
	{"status", "proxima_msgs::msg::dds_::Status_", 1},
	{"joint_states", "sensor_msgs::msg::dds_::JointState_", 0},
	{"cloud", "sensor_msgs::msg::dds_::PointCloud2_", 0},
};

const char *px_bridge_topic_short_name(enum px_bridge_topic t)
{
	return (unsigned)t < PX_BRIDGE_TOPIC__COUNT ? topics[t].name : NULL;
}

const char *px_bridge_topic_type_name(enum px_bridge_topic t)
{
	return (unsigned)t < PX_BRIDGE_TOPIC__COUNT ? topics[t].type : NULL;
}

int px_bridge_topic_reliable(enum px_bridge_topic t)
{
	return (unsigned)t < PX_BRIDGE_TOPIC__COUNT ? topics[t].reliable : 0;
}

void px_bridge_config_default(struct px_bridge_config *c)
{
	if (!c)
		return;
	memset(c, 0, sizeof(*c));
	c->ns = "proxima";
	c->interface = "lo";
	c->discovery = PX_BRIDGE_DISCOVERY_AUTO;
	c->frame_id = "world";
	c->tool_pose_rate_hz = 100;
	c->proxy_pose_rate_hz = 100;
	c->wrench_rate_hz = 100;
	c->distance_rate_hz = 50;
	c->status_rate_hz = 10;
}

/* ROS 2 name rules for the namespace (the config's, for the dds
 * device's topics too). */
static const char *ns_problem(const char *ns)
{
	return px__ros_name_problem(ns, PX_BRIDGE_NAME_MAX);
}

/* Interface names and addresses go into the XML as they are: only
 * characters that need no escaping. */
static const char *iface_problem(const char *s)
{
	const char *p;
	if (!s || !*s)
		return "must not be empty";
	if (strlen(s) >= PX_BRIDGE_NAME_MAX)
		return "is too long";
	for (p = s; *p; p++)
		if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') ||
		      (*p >= '0' && *p <= '9') || *p == '.' || *p == '-' ||
		      *p == '_' || *p == ':'))
			return "may hold only letters, digits, '.', '-', '_' "
			       "and ':' (an interface name or address)";
	return NULL;
}

/* Unicast discovery sends to this machine's loopback peers only. */
static const char *discovery_problem(int discovery, const char *iface)
{
	if (discovery == PX_BRIDGE_DISCOVERY_UNICAST &&
	    !px_bridge_is_loopback(iface))
		return "unicast discovery finds peers on loopback only: use "
		       "interface lo, or discovery auto or multicast";
	return NULL;
}

/* The file goes into a comma-separated list of Cyclone configuration
 * sources: no comma, no XML. */
static const char *security_problem(const char *s)
{
	if (!s)
		return NULL;
	if (!*s)
		return "must not be empty";
	if (strlen(s) >= 512)
		return "is too long";
	if (strpbrk(s, ",<>\"'"))
		return "may not hold ',', '<', '>' or quotes (a file path)";
	return NULL;
}

static const char *frame_problem(const char *s)
{
	if (!s)
		return "must be given";
	if (strlen(s) >= PX_BRIDGE_NAME_MAX)
		return "is too long";
	return NULL;
}

int px_bridge_config_check(const struct px_bridge_config *c, char *why,
			   size_t cap)
{
	const char *p;
	const double rates[] = {c ? c->tool_pose_rate_hz : 0,
				c ? c->proxy_pose_rate_hz : 0,
				c ? c->wrench_rate_hz : 0,
				c ? c->distance_rate_hz : 0,
				c ? c->status_rate_hz : 0};
	size_t i;
	if (!c) {
		snprintf(why, cap, "no config");
		return PX_E_INVAL;
	}
	if (c->domain_id < 0 || c->domain_id > 232) {
		snprintf(why, cap, "domain_id %lld is outside 0 .. 232",
			 (long long)c->domain_id);
		return PX_E_INVAL;
	}
	if ((p = ns_problem(c->ns))) {
		snprintf(why, cap, "namespace %s", p);
		return PX_E_INVAL;
	}
	if ((p = iface_problem(c->interface))) {
		snprintf(why, cap, "interface %s", p);
		return PX_E_INVAL;
	}
	if ((p = frame_problem(c->frame_id))) {
		snprintf(why, cap, "frame_id %s", p);
		return PX_E_INVAL;
	}
	if ((p = security_problem(c->security_file))) {
		snprintf(why, cap, "security_file %s", p);
		return PX_E_INVAL;
	}
	if (c->discovery < 0 || c->discovery > PX_BRIDGE_DISCOVERY_MULTICAST) {
		snprintf(why, cap, "unknown discovery %d", c->discovery);
		return PX_E_INVAL;
	}
	if ((p = discovery_problem(c->discovery, c->interface))) {
		snprintf(why, cap, "%s", p);
		return PX_E_INVAL;
	}
	for (i = 0; i < sizeof(rates) / sizeof(rates[0]); i++)
		if (!(rates[i] >= 0 && rates[i] <= PX_BRIDGE_MAX_RATE_HZ)) {
			snprintf(why, cap, "a rate is outside 0 .. %g Hz",
				 PX_BRIDGE_MAX_RATE_HZ);
			return PX_E_INVAL;
		}
	return PX_OK;
}

/* ---- config section ------------------------------------------------ */

static void bridge_check(struct px_config_reader *r,
			 const struct px_config_node *map, void *obj)
{
	const struct px_bridge_config *c = obj;
	const char *p;
	if ((p = ns_problem(c->ns)))
		px_config_reader_error(r, px_config_node_get(map, "namespace"),
				       "namespace", "'%s' %s", c->ns, p);
	if ((p = iface_problem(c->interface)))
		px_config_reader_error(r, px_config_node_get(map, "interface"),
				       "interface", "%s", p);
	if ((p = frame_problem(c->frame_id)))
		px_config_reader_error(r, px_config_node_get(map, "frame_id"),
				       "frame_id", "%s", p);
	if ((p = security_problem(c->security_file)))
		px_config_reader_error(r, px_config_node_get(map, "security_file"),
				       "security_file", "%s", p);
	if (!iface_problem(c->interface) &&
	    (p = discovery_problem(c->discovery, c->interface)))
		px_config_reader_error(r, px_config_node_get(map, "discovery"),
				       "discovery", "%s", p);
}

#define RATE_KEY(f, nm, def)                                                \
	K_DBL(struct px_bridge_config, f, nm, 0, 0, PX_BRIDGE_MAX_RATE_HZ, def)

static const struct px_config_key bridge_keys[] = {
	K_BOOL(struct px_bridge_config, enable, "enable", 0),
	K_INT(struct px_bridge_config, domain_id, "domain_id", 0, 0, 232, 0),
	{.name = "namespace", .type = PX_CONFIG_T_STRING,
	 .offset = offsetof(struct px_bridge_config, ns),
	 .flags = PX_CONFIG_NONEMPTY, .sdef = "proxima"},
	{.name = "interface", .type = PX_CONFIG_T_STRING,
	 .offset = offsetof(struct px_bridge_config, interface),
	 .flags = PX_CONFIG_NONEMPTY, .sdef = "lo"},
	K_ENUM(struct px_bridge_config, discovery, "discovery", 0,
	       discovery_names, PX_BRIDGE_DISCOVERY_AUTO),
	{.name = "frame_id", .type = PX_CONFIG_T_STRING,
	 .offset = offsetof(struct px_bridge_config, frame_id),
	 .flags = PX_CONFIG_NONEMPTY, .sdef = "world"},
	{.name = "security_file", .type = PX_CONFIG_T_STRING,
	 .offset = offsetof(struct px_bridge_config, security_file)},
	RATE_KEY(tool_pose_rate_hz, "tool_pose_rate_hz", 100),
	RATE_KEY(proxy_pose_rate_hz, "proxy_pose_rate_hz", 100),
	RATE_KEY(wrench_rate_hz, "wrench_rate_hz", 100),
	RATE_KEY(distance_rate_hz, "distance_rate_hz", 50),
	RATE_KEY(status_rate_hz, "status_rate_hz", 10),
};
SCHEMA(bridge_schema, "bridge", bridge_keys, bridge_check);

const struct px_config_schema *px_bridge_config_schema(void)
{
	return &bridge_schema;
}

int px_bridge_config_read(const struct px_config *cfg,
			  struct px_bridge_config *out,
			  struct px_config_diag *diag)
{
	if (!cfg || !out || !cfg->doc)
		return PX_E_INVAL;
	px_bridge_config_default(out);
	return px_config_read(cfg->doc, cfg->bridge, "bridge", &bridge_schema,
			      out, diag);
}

int px_bridge_topic_name(const char *ns, const char *name, char *buf,
			 size_t cap)
{
	int n;
	if (!ns || !name || !buf || !cap)
		return PX_E_INVAL;
	n = snprintf(buf, cap, "rt/%s/%s", ns, name);
	return n > 0 && (size_t)n < cap ? PX_OK : PX_E_RANGE;
}

/* An interface given as an address (digits, dots and colons only) is
 * matched by address, anything else by name. */
static int is_address(const char *s)
{
	for (; *s; s++)
		if (!((*s >= '0' && *s <= '9') || *s == '.' || *s == ':'))
			return 0;
	return 1;
}

int px_bridge_is_loopback(const char *iface)
{
	return iface && (!strcmp(iface, "lo") || !strncmp(iface, "127.", 4) ||
			 !strcmp(iface, "::1") || !strcmp(iface, "localhost"));
}

/*
 * Unicast discovery: participant indices are given out automatically
 * (each process on the machine its own ports) and discovery messages go
 * to the ports of the first PX_BRIDGE_MAX_PARTICIPANTS indices on
 * localhost, so no multicast is needed (CI machines often have none on
 * loopback). Multicast: Cyclone's defaults on the interface.
 */
int px_bridge_dds_config(const struct px_bridge_config *c, char *buf,
			 size_t cap)
{
	char why[160], thr[640] = "";
	int n, unicast;
	if (!buf || !cap)
		return PX_E_INVAL;
	buf[0] = '\0';
	if (px_bridge_config_check(c, why, sizeof(why)) != PX_OK)
		return PX_E_INVAL;
	if (c->thread_priority > 0 && c->thread_priority < 100) {
		static const char *const names[] = {"recv", "dq.user", "tev"};
		size_t i, k = 0;
		k += (size_t)snprintf(thr + k, sizeof(thr) - k, "<Threads>");
		for (i = 0; i < 3; i++)
			k += (size_t)snprintf(
				thr + k, sizeof(thr) - k,
				"<Thread name=\"%s\"><Scheduling><Class>realtime"
				"</Class><Priority>%d</Priority></Scheduling>"
				"</Thread>",
				names[i], c->thread_priority);
		snprintf(thr + k, sizeof(thr) - k, "</Threads>");
	}
	unicast = c->discovery == PX_BRIDGE_DISCOVERY_UNICAST ||
		  (c->discovery == PX_BRIDGE_DISCOVERY_AUTO &&
		   px_bridge_is_loopback(c->interface));
	n = snprintf(buf, cap,
		     "<CycloneDDS><Domain Id=\"any\"><General><Interfaces>"
		     "<NetworkInterface %s=\"%s\"%s/></Interfaces>"
		     "<AllowMulticast>%s</AllowMulticast></General>"
		     "<Discovery><ParticipantIndex>auto</ParticipantIndex>"
		     "<MaxAutoParticipantIndex>%d</MaxAutoParticipantIndex>"
		     "%s</Discovery>%s</Domain></CycloneDDS>",
		     is_address(c->interface) ? "address" : "name",
		     c->interface,
		     !unicast && px_bridge_is_loopback(c->interface)
			     ? " multicast=\"true\""
			     : "",
		     unicast ? "false" : "true", PX_BRIDGE_MAX_PARTICIPANTS,
		     unicast ? "<Peers><Peer address=\"127.0.0.1\"/></Peers>"
			     : "",
		     thr);
	if (n > 0 && (size_t)n < cap && c->security_file)
		n += snprintf(buf + n, cap - (size_t)n, ",file://%s",
			      c->security_file);
	return n > 0 && (size_t)n < cap ? PX_OK : PX_E_RANGE;
}
