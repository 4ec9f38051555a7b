/* needs.h - the compiler's analysis of what a compiled scene needs (prefix
 * needs_): features and per-frame bounds, docs/needs.md. */
#ifndef NEEDS_H
#define NEEDS_H

#include <stdint.h>
#include <stdio.h>

#include "scene.h"

typedef struct {
    scn_needs needs;
    uint32_t all_edges, all_surfaces;     /* every polygon at once (the bound without analysis) */
    uint32_t wall_edges, wall_surfaces;   /* walls: the most for any eye position */
    uint32_t worst_leaf;                  /* the leaf whose region gives wall_edges */
    uint32_t plane_edges, plane_surfaces; /* floors and ceilings: the most for any eye height */
} needs_report;

/* Analyse s (parsed by scene_parse; its own needs record is not read). look: the
 * scene lets the camera look up and down. 0, or -1 when out of memory. */
int needs_analyse(const scene *s, int look, needs_report *r);

/* The analysis as text (what is needed and why), and as a C header for a build
 * compiled for this scene (firmware/build_config.h). */
void needs_print(FILE *f, const char *name, const scene *s, const needs_report *r);
void needs_write_config(FILE *f, const char *name, const scene *s, const scn_needs *n);

#endif
