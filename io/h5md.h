/*
 * h5md.h — the trajectory writer shared by both engines (the standalone stepper and the
 * LIGGGHTS dump style `h5md/jdem`).  C11 on top of the HDF5 C library; it writes the H5MD 1.1
 * layout of docs/output.md plus an XDMF sidecar so that ParaView opens the file directly.
 *
 * Layout (all floating-point data float64, SI units; N particles sorted by id; F frames;
 * docs/output.md describes it for readers):
 *   /h5md                       attrs version = [1, 1]; groups author (attr name: meta.author,
 *                               else $JDEM_AUTHOR, else the user name), creator (attrs name,
 *                               version), modules/units (attrs version = [1, 0], system = "SI")
 *   /parameters                 attrs engine, scene_name, case_name, dt [s]; dataset "scene"
 *                               (variable-length string: the resolved scene, YAML) when given
 *   /particles/all/box          attrs dimension = 3, boundary = ["none","none","none"]
 *   /particles/all/{id,species,radius,mass}        [N] time-independent (int64, int32, f64, f64);
 *                               a growing set: id/{step,time,value} [F][N], -1 in empty rows
 *                               (fill value -1; vectors NaN there), the particle axis extendible
 *   /particles/all/{position,velocity,angular_velocity,force,torque}/{step,time,value}
 *                               step [F] int64, time [F] f64, value [F][N][3] f64
 *   /observables/NAME/{step,time,value}            value [F] f64 (counts stored as f64 too)
 *   /jdem/vertex_index          [N] int64 0..N-1: the sidecar's vertex connectivity (at close)
 *   /jdem/walls/...             the walls and their quadrilateral mesh (jd_h5md_set_walls)
 *   /jdem/bond_lines/{rows,frame_start,frame_count}  the bonds intact at each frame as row
 *                               pairs (at close, from the bond tables)
 *   /jdem/bonds/{ids,type,formed_step}             every bond formed, in formation order
 *                               (jd_h5md_write_bonds); ids [B][2] int64 is also the H5MD tuple
 *                               list /connectivity/bonds (particles_group: object reference)
 *   /jdem/broken_bonds/{step,time,ids,mode,position,normal_force,shear_force,
 *                               twisting_moment,bending_moment,sigma_max,tau_max}
 *                               one row per broken bond (jd_h5md_write_bond_breaks); ids is
 *                               also the tuple list /connectivity/broken_bonds; docs/scenes.md
 *                               "Bonds" gives units and meaning
 *
 * Fault safety: the file is written as PATH.part, which is locked (a second run on the same
 * path fails without touching it) and never written through a link; jd_h5md_close(ok = 1)
 * writes the sidecar as SIDECAR.part, then renames PATH.part to PATH and the sidecar into
 * place, so the previous pair stays until both new files are complete.  Every frame is
 * flushed, so a run that dies leaves a readable PATH.part with every frame so far.
 * jd_h5md_close(ok = 0) keeps it under PATH.part (an aborted run never masquerades as
 * complete); after a failed write or close, PATH.part is kept only if it can be read, else it
 * is removed and err says that nothing could be kept.
 */
#ifndef JDEM_IO_H5MD_H
#define JDEM_IO_H5MD_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct jd_h5md jd_h5md;

/* The particle set: n rows, each the row of one particle for the whole run.  For a fixed set
 * (growing = 0) the rows are the particles sorted by id.  For a set that changes (growing = 1,
 * H5MD 1.1's time-dependent particle count) id is written per frame, -1 for an empty row, and
 * each frame gives its rows (jd_h5md_frame.rows): a row keeps its particle (the caller assigns
 * rows, e.g. in order of arrival), rows are only added, never removed. */
typedef struct jd_h5md_particles {
    size_t n;
    const int64_t *id;      /* the particle of each row; in a frame's rows, -1: empty */
    const int32_t *species; /* index into the scene's material list (0-based) */
    const double *radius;   /* [m]  */
    const double *mass;     /* [kg] */
    int growing;            /* create only: 1 = the set changes during the run */
} jd_h5md_particles;

/* Run metadata written under /parameters.  Any pointer may be NULL. */
typedef struct jd_h5md_meta {
    const char *creator;         /* "jdem" or "liggghts-jdem" */
    const char *creator_version; /* e.g. "0.1.0" */
    const char *scene_name;
    const char *case_name;
    const char *scene_yaml;      /* the resolved scene text, stored as /parameters/scene */
    double dt;                   /* [s] */
    const char *author;          /* /h5md/author/name; NULL: $JDEM_AUTHOR, else the user name */
} jd_h5md_meta;

/* One frame of per-particle data, each an array of 3n doubles (x0 y0 z0 x1 ...), sorted by id.
 * Any of velocity..torque may be NULL, in which case that group is not written for this run
 * (decide at the first frame and keep it). */
typedef struct jd_h5md_frame {
    int64_t step;
    double time; /* [s] */
    const double *position;
    const double *velocity;
    const double *angular_velocity;
    const double *force;
    const double *torque;
    /* growing sets only: this frame's rows (n >= the previous frame's n; rows beyond it are new
     * and bring their species, radius and mass); the vectors above have 3 rows->n entries, and
     * those of an empty row are not read (the file holds NaN there). */
    const jd_h5md_particles *rows;
} jd_h5md_frame;

/* Create PATH.part.  Returns NULL and writes a one-line reason into err on failure. */
jd_h5md *jd_h5md_create(const char *path, const jd_h5md_meta *meta,
                        const jd_h5md_particles *particles, char *err, size_t errlen);

/* Append one frame (flushes).  Returns 0 on success, -1 with a reason in err. */
int jd_h5md_write_frame(jd_h5md *h, const jd_h5md_frame *frame, char *err, size_t errlen);

/* Append one scalar sample to /observables/NAME (created on first use).  Observables may be
 * sampled on their own schedule.  Returns 0 or -1 with a reason in err. */
int jd_h5md_write_observable(jd_h5md *h, const char *name, int64_t step, double time,
                             double value, char *err, size_t errlen);

/* A wall as drawn in the output (/jdem/walls): its geometry at time 0 and its motion, a rigid
 * translation x(t) = x(0) + velocity t (both engines move plane and cylinder walls so), or for
 * a mesh whose engine moves it otherwise (LIGGGHTS' fix move/mesh rotate) its triangles at
 * each frame (jd_h5md_move_mesh). */
typedef struct jd_h5md_wall {
    const char *name;
    int type;               /* 0 plane (the quadrilateral corners), 1 cylinder (axis, radius),
                               2 triangle mesh (triangles) */
    double corners[4][3];   /* [m] plane */
    double axis[2][3];      /* [m] cylinder: end points of the axis segment */
    double radius;          /* [m] cylinder */
    int inside;             /* cylinder: 1 container, 0 obstacle */
    double velocity[3];     /* [m/s] */
    size_t n_triangles;     /* mesh: its triangles, in the STL's order */
    const double (*triangles)[3][3]; /* [m] mesh: their corners at time 0 */
    int moved;              /* mesh: 1 = the engine gives its triangles at every frame */
} jd_h5md_wall;

/* Record the run's walls (once, before the first frame; n may be 0).  Each frame then carries
 * their surfaces for the sidecar: planes as their quadrilateral, cylinders as
 * JD_H5MD_CYLINDER_FACETS quadrilaterals around the axis.  Returns 0 or -1 with err. */
int jd_h5md_set_walls(jd_h5md *h, size_t n, const jd_h5md_wall *walls, char *err, size_t errlen);
#define JD_H5MD_CYLINDER_FACETS 32

/* The triangles (n_triangles of them, as set) of mesh wall `wall` (its index in the set_walls
 * list; a wall given with moved = 1) where they are now: the next frames draw them there.
 * 0, or -1 with err (not such a wall). */
int jd_h5md_move_mesh(jd_h5md *h, size_t wall, const double (*triangles)[3][3], char *err,
                      size_t errlen);

/* A bond as recorded in /connectivity. */
typedef struct jd_h5md_bond {
    int64_t id[2];       /* particle ids, id[0] < id[1] */
    int32_t type;        /* index of its bond type in the resolved scene's bond_types */
    int64_t formed_step; /* step at which it formed */
} jd_h5md_bond;

/* Append n bonds (formed at some step) to /connectivity/bonds, bond_type, bond_formed_step; the
 * datasets are created by the first call (n may be 0: an empty list).  The caller orders them
 * (docs/scenes.md: by step, then ids).  Returns 0 or -1 with a reason in err. */
int jd_h5md_write_bonds(jd_h5md *h, size_t n, const jd_h5md_bond *bonds, char *err,
                        size_t errlen);

/* One broken-bond event. */
typedef struct jd_h5md_bond_break {
    int64_t step;
    double time;            /* [s] */
    int64_t id[2];          /* particle ids, id[0] < id[1] */
    int32_t mode;           /* jd_bond_mode: 1 tension, 2 shear */
    double position[3];     /* bond point x_C [m] */
    double normal_force;    /* > 0 in compression [N] */
    double shear_force;     /* magnitude [N] */
    double twisting_moment; /* magnitude [N m] */
    double bending_moment;  /* magnitude [N m] */
    double sigma_max;       /* [Pa] */
    double tau_max;         /* [Pa] */
} jd_h5md_bond_break;

/* Append n events to /connectivity/broken_bonds (created by the first call; n may be 0).  The
 * caller orders them (by step, then ids).  Returns 0 or -1 with a reason in err. */
int jd_h5md_write_bond_breaks(jd_h5md *h, size_t n, const jd_h5md_bond_break *events, char *err,
                              size_t errlen);

/* Close the file.  ok = 1: write the XDMF sidecar (PATH with its extension replaced by .xdmf)
 * and rename both into place.  ok = 0: leave PATH.part.  Returns 0 or -1 with err (then
 * PATH.part is kept if readable, else removed, and err says which). */
int jd_h5md_close(jd_h5md *h, int ok, char *err, size_t errlen);

#ifdef __cplusplus
}
#endif
#endif /* JDEM_IO_H5MD_H */
