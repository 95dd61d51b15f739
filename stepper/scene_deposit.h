/*
 * scene_deposit.h — internal to the scene reader: one frame of an H5MD trajectory
 * (scene_deposit_h5md.c), the particles of a scene's particles_from entry (scene_deposit.c).
 */
#ifndef JDEM_SCENE_DEPOSIT_H
#define JDEM_SCENE_DEPOSIT_H

#include <stddef.h>
#include <stdint.h>

/* The particle slots of one frame, in the file's order (sorted by id; id -1: an empty slot). */
typedef struct dep_frame {
    size_t n;                  /* slots                                                  */
    int64_t *id;               /* [n] particle ids, -1 for an empty slot                 */
    int32_t *species;          /* [n] index into materials                               */
    double *radius;            /* [n] [m]                                                */
    double *position;          /* [3n] [m]                                               */
    double *velocity;          /* [3n] [m/s], NULL unless asked for                      */
    double *angular_velocity;  /* [3n] [rad/s], NULL unless asked for                    */
    char **materials;          /* [n_materials] the source scene's material names, in order */
    size_t n_materials;
    /* The bonds intact at the frame (/jdem/bond_lines), read only when asked for: */
    size_t n_lines;            /* bonds                                                  */
    int64_t *line_row;         /* [2 n_lines] the slots of their two particles           */
    int32_t *line_type;        /* [n_lines] index into bond_types                        */
    char **bond_types;         /* [n_bond_types] the source scene's bond type names, in order */
    size_t n_bond_types;
} dep_frame;

/* Read frame `frame` (Python-style: -1 is the last) of FILE, with the velocities and the intact
 * bonds if asked (a trajectory without bonds has none).  Returns 0, or -1 with a one-line
 * message naming the file and what would be valid in msg. */
int dep_read_frame(const char *file, int64_t frame, int velocities, int bonds, dep_frame *fr,
                   char *msg, size_t len);
void dep_free_frame(dep_frame *fr);

#endif
