/*
 * px.h - umbrella header: include this to get all of proxima's public API.
 * Each module also has its own header (px_<module>.h) for finer use.
 */
#ifndef PX_H
#define PX_H

#include "px_base.h"
#include "px_arena.h"
#include "px_file.h"
#include "px_math.h"
#include "px_nurbs.h"
#include "px_obj.h"
#include "px_fault.h"
#include "px_loop.h"
#include "px_param.h"
#include "px_ring.h"
#include "px_rt.h"
#include "px_stats.h"
#include "px_config.h"
#include "px_codec.h"
#include "px_dev.h"
#include "px_sim.h"
#include "px_hid.h"
#include "px_usb.h"
#include "px_can.h"
#include "px_canopen.h"
#include "px_gpio.h"
#include "px_control.h"
#include "px_scene.h"

#endif
