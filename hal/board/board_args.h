/* board_args.h - the display board's options, from the semihosting command line
 * (prefix board_args_). The renderer's parser (hal/bare/args.c) knows the
 * renderer's options only; the board has one of its own. The first word is the
 * program (QEMU passes the -kernel file's name), as in hal/bare/args.c.
 *   --frames N     after N frames shown, log a summary and idle (N >= 1)
 *   --log-frames   log one line per frame shown (with the CRC-32 of the page,
 *                  computed after the frame's handling); without it the board
 *                  logs a line of counters every BOARD_LOG_EVERY frames
 */
#ifndef BOARD_ARGS_H
#define BOARD_ARGS_H

#include <stdint.h>

typedef struct {
    uint32_t frames;    /* 0: run until stopped */
    uint8_t log_frames; /* --log-frames */
} board_args;

/* Returns 0, or -1 with a message in err. */
int board_args_parse(board_args *a, const char *cmdline, char *err, uint32_t err_size);

#endif
