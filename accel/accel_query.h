/* accel_query.h - the parser's parse-time geometry queries (core/geom_env.h)
 * answered by geom_shape (geom_shape.h): one intersector for rendering and
 * for trace()/inside(). Unbounded shapes (poly, quadric) are clipped to a
 * cube of half side ACCEL_QUERY_EXTENT around the origin, and their hits are
 * searched in windows of t that grow from ACCEL_QUERY_WINDOW by 4x: the
 * quartic root finder loses the near root on long intervals (measured: a
 * quartic whose nearest hit POV-Ray puts at t = 1.588451 gave t = 16.18 on
 * one interval of 2e5, 1.96 on 2e4, 1.588385 on 2e3 and 1.588451 on 200).
 * Only hits at t > 0 are reported for them. */
#ifndef PT_ACCEL_QUERY_H
#define PT_ACCEL_QUERY_H
#include "geom_env.h"

#define ACCEL_QUERY_EXTENT 1.0e5
#define ACCEL_QUERY_WINDOW 100.0

const geom_env *accel_geom_env(void);

#endif
