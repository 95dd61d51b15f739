/*
 * mesh_cells.h — which triangles of a mesh may lie within a distance of a point: a uniform grid
 * of cubic cells over the mesh's bounding box, each cell listing the triangles whose bounding
 * box overlaps it.  The mesh walls' candidate search (mesh_walls.c) asks it for each particle
 * at a rebuild instead of testing every triangle, so a rebuild costs about (particles near the
 * mesh) x (triangles per cell) closest-feature tests rather than particles x triangles.
 *
 * The answer is a superset of the triangles within the distance (a triangle within d of x has
 * its bounding box within d of x along every axis, so their cell ranges overlap), in ascending
 * triangle id: the caller's exact test then keeps the same candidates, in the same order, as a
 * test of every triangle.
 */
#ifndef JDEM_MESH_CELLS_H
#define JDEM_MESH_CELLS_H

#include <stddef.h>
#include <stdint.h>

typedef struct jd_mesh_cells {
    double lo[3];        /* the grid's lower corner: the mesh's bounding box's [m]          */
    double inv_h;        /* 1 / the cell edge [1/m]                                        */
    int n[3];            /* cells along each axis                                          */
    size_t *start;       /* [cells + 1] offsets into tri                                   */
    int32_t *tri;        /* the triangles of each cell, ascending                          */
    size_t cap_cells, cap_tri;
    uint32_t *stamp;     /* [triangles] the query that last took each triangle            */
    uint32_t query;      /* the current query's number                                     */
    size_t n_tri;        /* triangles of the mesh the grid was built for                   */
    int32_t *found;      /* the last query's triangles, ascending                          */
    size_t cap_found;
} jd_mesh_cells;

/* The grid of the ntri triangles corner[t] [m] for queries of distance up to reach_max [m]:
 * cells of edge at least 2 reach_max (a query box then spans at most 2 cells per axis), larger
 * when the mesh's box would hold more than 8 cells per triangle.  0, or -1 out of memory. */
int sim_mesh_cells_build(jd_mesh_cells *g, size_t ntri, const double (*corner)[3][3], double reach_max);

/* The triangles whose bounding box may lie within reach [m] (at most the build's reach_max) of
 * x [m], ascending, in g->found; returns their number, or -1 out of memory. */
long sim_mesh_cells_near(jd_mesh_cells *g, const double x[3], double reach);

void sim_mesh_cells_free(jd_mesh_cells *g);

#endif
