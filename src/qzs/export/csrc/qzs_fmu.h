/* qzs: the isolator as an FMU, independent of the FMI version (fmi2_api.c, fmi3_api.c).
 *
 * An instance holds every variable by value reference in one array (qzs_fmu_variables.h,
 * written by qzs at export: names, types, causalities, the channel each output shows) and the
 * run it steps (qzs_model.h). Parameters are checked and packed as qzs packs them
 * (qzs.engine.prepare) when initialisation ends, with the steps qzs would refuse (unstable, too
 * coarse for the excitation) refused and one above the step the export chose for accuracy
 * warned of. A communication step of any positive length is taken on the grid of internal
 * steps from t = 0 that qzs steps: whole grid steps exactly as qzs takes them, and a grid step
 * that a communication point falls inside split in two at that point (the sampled controller
 * runs at the grid points only, so its timing does not change). The outputs are the recorded
 * channels at the step's end. A call the FMU cannot honour returns QZS_FMU_ERROR after
 * logging why; nothing is left half done.
 */
#ifndef QZS_FMU_H
#define QZS_FMU_H

#include <stddef.h>
#include <stdint.h>

#include "qzs_fmu_variables.h"
#include "qzs_model.h"

enum { QZS_FMU_OK = 0, QZS_FMU_WARNING = 1, QZS_FMU_ERROR = 3 };

/* How the FMU reports: status, category ("logStatusError", ...), message. */
typedef void (*QzsFmuLogger)(void *environment, int status, const char *category,
                             const char *message);

typedef struct {
    double values[QZS_FMU_N_VARIABLES]; /* every variable by value reference */
    int initialized;                    /* initialisation ended: parameters fixed */
    int failed;                         /* a step failed: only reset or free is possible */
    double time;                        /* the communication point reached [s] */
    double offset;                      /* how far past the grid point run.step*dt it is [s] */
    double start_time;                  /* [s] */
    int stop_defined;                   /* the importer gave a stop time... */
    double stop_time;                   /* ...this one [s] */
    double table[10];                   /* input mode: the base motion's cubic over a step */
    int has_previous;                   /* input mode: an earlier communication point... */
    double previous_time;               /* ...its time [s] */
    double previous_acceleration;       /* ...and base acceleration [m/s^2] */
    /* the run's model row: the controller's blocks, then the spring law (the plant keeps it
     * by pointer) */
    double model[QZS_N_MODEL + QZS_FMU_SPRING_SIZE];
    QzsRun run;
    QzsFmuLogger log;
    void *environment;
} QzsFmu;

/* Set the start values of every variable; nothing is checked yet. */
void qzs_fmu_reset(QzsFmu *fmu, double start_time);
/* The experiment: its start time [s], and its stop time [s] if `stop_defined`. */
void qzs_fmu_setup(QzsFmu *fmu, double start_time, int stop_defined, double stop_time);
/* Set a variable: an error for an unknown reference, a wrong type or causality, a fixed
 * parameter after initialisation, a non-finite value. type: 'F' Float64/Real, 'I' integer,
 * 'B' Boolean. */
int qzs_fmu_set(QzsFmu *fmu, unsigned int reference, char type, double value);
/* Get a variable (its type must match). */
int qzs_fmu_get(QzsFmu *fmu, unsigned int reference, char type, double *value);
/* How many values `reference` holds into *size: an FMI 3 array's length, 1 for a scalar; an
 * error for no variable (an array's later elements have no reference of their own). */
int qzs_fmu_size(QzsFmu *fmu, unsigned int reference, size_t *size);
/* End initialisation: check and pack the parameters, the initial state as qzs starts a run.
 * QZS_FMU_WARNING: initialised, with a warning logged. */
int qzs_fmu_initialize(QzsFmu *fmu);
/* One communication step from `current` [s] of length `step` [s] (any positive length, within
 * the stop time). */
int qzs_fmu_do_step(QzsFmu *fmu, double current, double step);
/* Log through the instance's logger (printf-style). */
void qzs_fmu_log(QzsFmu *fmu, int status, const char *format, ...);

#endif /* QZS_FMU_H */
