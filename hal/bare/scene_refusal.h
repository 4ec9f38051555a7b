/* scene_refusal.h - why a bare-metal firmware refuses its built-in scene, in
 * the words the host tools use (prefix scene_refusal_): a feature or bound the
 * build leaves out, or the loader's status with the section and record it
 * names. Shared by hal/mps2 and hal/pcvga, which each add their own prefix. */
#ifndef BARE_SCENE_REFUSAL_H
#define BARE_SCENE_REFUSAL_H

#include "scene.h"

/* "the built-in scene NAME ...; refusing to run" into buf (NUL-terminated);
 * st is what eng_init returned (not SCENE_OK), se its details. Returns the length. */
int scene_refusal_format(char *buf, int size, const char *scene_name, scene_status st, const scene_error *se);

#endif
