/* ftcsim's export library: the FMI-version-independent core (core.c).
 *
 * One FMU binary = this core + one front end (fmi2.c or fmi3.c), compiled by fmus/export_library.py.
 * The core embeds Python and drives the FMU's pythonfmu / pythonfmu3 slave class (the Python-side
 * protocol of pythonfmu 0.7 and pythonfmu3 0.3: get_real / get_float64 ..., do_step, _get_fmu_state ...),
 * and keeps the rules that make the FMU safe in any host (fmus/native/README.md):
 *
 *   - every entry point looks its instance up in a registry before touching it: NULL, freed or foreign
 *     pointers get an error status and touch nothing (freed instances stay in a quarantine, so their
 *     addresses are not reused for a while);
 *   - the FMI state machine: a call in the wrong mode is an error; after an error only the recovery calls
 *     (reset, set FMU state, free FMU state, free instance, set debug logging) are served; after a fatal
 *     error none but free instance; every refusal is logged with the error that caused it;
 *   - every Python exception becomes a status (Error, or Fatal for MemoryError / SystemExit /
 *     KeyboardInterrupt) with a logged category and message;
 *   - the library owns no Python object that points into it (no C functions, no types), never finalises
 *     the interpreter, and at unload releases only its own C memory, once.
 */
#ifndef FTCSIM_EXPORT_CORE_H
#define FTCSIM_EXPORT_CORE_H

#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <stddef.h>
#include <stdint.h>

/* statuses: the same numbers in FMI 2.0 and FMI 3.0 */
enum { FS_OK = 0, FS_WARNING = 1, FS_DISCARD = 2, FS_ERROR = 3, FS_FATAL = 4 };

/* modes (bit flags, so that a function can name the modes it is allowed in) */
enum {
    FS_INSTANTIATED = 1 << 0,
    FS_CONFIGURATION = 1 << 1, /* FMI 3 only */
    FS_INIT = 1 << 2,
    FS_STEP = 1 << 3,
    FS_TERMINATED = 1 << 4,
    FS_ERRORED = 1 << 5,
    FS_FATAL_MODE = 1 << 6,
};

/* value kinds exchanged with the Python slave */
typedef enum { FS_REAL, FS_INT32, FS_INT64, FS_UINT64, FS_BOOL_INT, FS_BOOL_BYTE, FS_STRING } fs_kind;

typedef struct fs_state fs_state;
typedef struct fs_instance fs_instance;

struct fs_state {
    uint64_t magic;
    fs_instance *owner;
    PyObject *obj;     /* what the slave's _get_fmu_state returned */
    PyObject *bytes;   /* its serialisation, kept between "size" and "serialize" */
    int mode;          /* the instance's mode when the state was taken */
    int terminate_requested;
    double last_time;
    fs_state *next;
};

struct fs_instance {
    uint64_t magic;
    int fmi;                 /* 2 or 3 */
    char *name;
    char *resources;         /* decoded folder, no trailing separator */
    int mode;
    int logging_on;
    char **categories;       /* debug categories enabled by set-debug-logging; none: all */
    size_t n_categories;
    double last_time;        /* end of the last successful step */
    int terminate_requested; /* the slave's do_step returned false */
    char *error;             /* the message of the error that put the instance in error / fatal mode */
    unsigned long refusals;  /* calls refused since (fs_check) */
    PyObject *cls, *obj, *queue;
    fs_state *states;        /* live FMU states of this instance */
    char **strings;          /* strings returned by the last get-string, valid until the next call */
    size_t n_strings;
    /* the host's callbacks, interpreted by the front end (fs_emit) */
    void *host_env;
    void (*host_logger)(void);
};

/* -- provided by the front end ------------------------------------------------------------------------- */
/* hand one message to the host's logger (the front end knows the callback's signature) */
void fs_emit(fs_instance *c, int status, const char *category, const char *message);
extern const char *const FS_RECOVERY_CALLS; /* e.g. "fmi2Reset, fmi2SetFMUstate, ..." */

/* -- registry ------------------------------------------------------------------------------------------ */
/* the live instance behind a handle, or NULL (a note on stderr names the function): never dereferences an
 * unknown pointer */
fs_instance *fs_live(void *handle, const char *function);

/* -- logging and status -------------------------------------------------------------------------------- */
void fs_log(fs_instance *c, int status, const char *category, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
/* log the message and put the instance into error (FS_ERROR) or fatal (FS_FATAL) mode; returns status */
int fs_fail(fs_instance *c, int status, const char *fmt, ...) __attribute__((format(printf, 3, 4)));
/* FS_OK if the instance may serve `function` in its mode (one of `allowed`), else the status to return,
 * with the refusal logged (an error or fatal instance keeps its mode; a call out of order is an error) */
int fs_check(fs_instance *c, const char *function, int allowed);
const char *fs_mode_name(int mode);
void fs_set_debug_logging(fs_instance *c, int on, size_t n, const char *const categories[]);

/* -- life cycle ---------------------------------------------------------------------------------------- */
/* A new instance, or NULL with the reason logged through the given callbacks. `location` is the FMI 2
 * resource URI or the FMI 3 resource path; `token` the GUID / instantiation token. */
fs_instance *fs_instantiate(int fmi, const char *function, const char *name, const char *token,
                            const char *location, int visible, int logging_on, void *host_env,
                            void (*host_logger)(void));
void fs_free_instance(void *handle, const char *function);
int fs_reset(fs_instance *c, const char *function);

/* -- calls into the slave (mode already checked) ------------------------------------------------------- */
/* method(*args) with float arguments; `nargs` floats, `none_mask` bit i: pass None instead of args[i] */
int fs_call(fs_instance *c, const char *function, const char *method, int nargs, const double *args,
            unsigned none_mask);
/* do_step(t, h): FS_OK / FS_DISCARD / error; *terminate set when the slave asks to stop */
int fs_do_step(fs_instance *c, const char *function, double t, double h, int *terminate);
int fs_get(fs_instance *c, const char *function, const char *method, fs_kind kind, const unsigned int *vr,
           size_t nvr, void *values, size_t nvalues);
int fs_set(fs_instance *c, const char *function, const char *method, fs_kind kind, const unsigned int *vr,
           size_t nvr, const void *values, size_t nvalues);

/* -- FMU state ----------------------------------------------------------------------------------------- */
fs_state *fs_state_of(fs_instance *c, void *handle); /* a live state of c, or NULL */
int fs_get_state(fs_instance *c, const char *function, void **inout);
int fs_set_state(fs_instance *c, const char *function, void *handle);
int fs_free_state(fs_instance *c, const char *function, void **inout);
int fs_state_size(fs_instance *c, const char *function, void *handle, size_t *size);
int fs_serialize_state(fs_instance *c, const char *function, void *handle, unsigned char *bytes, size_t size);
int fs_deserialize_state(fs_instance *c, const char *function, const unsigned char *bytes, size_t size,
                         void **out);

/* -- resources ----------------------------------------------------------------------------------------- */
/* The folder a resource location names (RFC 3986 percent-decoding of file:/, file:///, file://localhost/
 * URIs; a plain path as it is), malloc'ed without trailing separator, or NULL with the reason in why. */
char *fs_resource_folder(const char *location, char *why, size_t why_size);

#endif
