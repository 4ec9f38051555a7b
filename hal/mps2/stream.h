/* stream.h - sending rendered frames over UART0 (prefix stream_).
 *
 * Two encodings, one chosen at build time (mk/mps2.mk, STREAM=):
 *   framelink  stream_fl.c: the project's frame link (hal/serial/framelink.h,
 *              docs/frame-link.md): COBS-framed messages with CRC-32, hello,
 *              palette, keyframes and deltas, acks as flow control. The default
 *              when hal/serial has its sources.
 *   raw        stream_raw.c: uncompressed records, no acks (for bring-up and as
 *              a fallback; tests/test_firmware.py reads it).
 *
 * Every frame carries its information as the firmware used it: the frame number,
 * the camera (x, y, z and the angle in degrees as raw 16.16; look in pixels),
 * the render and present modes, and the CRC-32 of the 64,000 bytes of the shown
 * page.
 */
#ifndef MPS2_STREAM_H
#define MPS2_STREAM_H

#include <stdint.h>
#include "engine.h"

/* Flow control (frame link): wait for the receiver's acks or not. AUTO waits
 * only once the receiver has been heard from (an ack or a keyframe request),
 * so capturing to a file never stalls and a live receiver is never overrun. */
typedef enum { STREAM_ACKS_AUTO, STREAM_ACKS_ON, STREAM_ACKS_OFF } stream_acks;

void stream_set_acks(stream_acks mode);

/* Before the first frame: hello (naming the scene: its name and the CRC-32 of
 * its compiled blob, which a capture records to reproduce the frames), palette.
 * Returns 0 or -1. */
int stream_begin(const engine *e, const char *scene_name, uint32_t scene_crc);

/* Send the page shown now as frame frame_no, with its information, after the
 * frame before it. Returns 0, or -1 if the link failed. */
int stream_frame(const engine *e, uint32_t frame_no);

/* After the last frame (waits for the last acks, within the ack timeout). */
void stream_end(uint32_t frames);

/* The encoding ("raw" or "framelink"), and whether text may go on the UART
 * between its messages without costing the receiver anything. */
const char *stream_kind(void);
int stream_text_ok(void);

/* A summary line of the link's counters for the closing message ("" if none). */
const char *stream_summary(void);

#endif
