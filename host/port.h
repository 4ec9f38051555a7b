/* port.h - open a frame-link port (prefix port_): the one parser of the PORT
 * argument that build/display, build/emu --link and build/render --link take. */
#ifndef PORT_H
#define PORT_H

#include <stddef.h>

#define PORT_DEFAULT_BAUD 115200

/* Open PORT for the frame link:
 *   /dev/ttyUSB0, /dev/pts/3   a serial device or pty, set raw at baud
 *   socket://HOST:PORT         a TCP connection (this end is the client);
 *                              PORT a decimal number in 1..65535, nothing else
 *   -                          stdin (fd 0), read only
 *   any other file             opened as it is (a captured stream: read only);
 *                              a FIFO is refused (it would echo this end's bytes)
 * Returns the file descriptor, with *writable set when bytes can go out on it
 * (not on stdin, regular files, or files only readable); or -1 with a message
 * naming PORT in err. */
int port_open(const char *port, long baud, int *writable, char *err, size_t errlen);

#endif
