/*
 * limits.c — the default size limits of a request (codec_limits).
 *
 * How it fits: validate.c checks every count in a request (joints,
 * elements, speeds, modes, the size of the result) against a codec_limits
 * before anything is allocated from it; request.c checks the text length.  The
 * daemon starts from these defaults and overrides them from its
 * configuration; the CLI uses them as they are.
 */
#include "codec.h"

void codec_default_limits(codec_limits *lim)
{
    lim->max_request_bytes = (size_t)16 * 1024 * 1024;
    lim->max_joints = 1000;
    lim->max_sections = 1000;
    lim->max_members = 1000;
    lim->max_point_masses = 1000;
    lim->max_elements = 2000;
    lim->max_speeds = 1001;
    lim->max_modes = 200;
    lim->max_shape_values = 4000000;
    lim->max_result_bytes = 50000000;
    lim->max_coordinates = SM_DENSE_MAX_DEFAULT;
    lim->max_solve_seconds = 0;
    lim->max_frame_dofs = 1200;
}
