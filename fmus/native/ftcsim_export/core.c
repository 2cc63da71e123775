/* ftcsim's export library, FMI-version-independent core: see core.h and fmus/native/README.md. */
#include "core.h"

#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#define LIVE_MAGIC 0x66746373696d4c56ULL  /* "ftcsimLV" */
#define DEAD_MAGIC 0x66746373696d4444ULL  /* "ftcsimDD" */
#define STATE_MAGIC 0x66746373696d5354ULL /* "ftcsimST" */
#define QUARANTINE 1024                   /* freed instances kept before their memory is reused */
#define MAX_ORPHAN_NOTES 100              /* notes on stderr about calls on no live instance */

static const char SERIAL_MAGIC[8] = {'F', 'T', 'C', 'S', 'I', 'M', 'S', 1};
#define SERIAL_HEADER 24 /* magic, int32 mode, int32 terminate flag, float64 last time */

/* -- registry -------------------------------------------------------------------------------------------- */
static pthread_mutex_t registry_lock = PTHREAD_MUTEX_INITIALIZER;
static fs_instance **live;
static size_t n_live, cap_live;
static fs_instance *quarantine[QUARANTINE];
static size_t quarantine_next;
static int orphan_notes;

static void release_c_memory(fs_instance *c);

fs_instance *fs_live(void *handle, const char *function)
{
    fs_instance *found = NULL;
    if (handle != NULL) {
        pthread_mutex_lock(&registry_lock);
        for (size_t i = 0; i < n_live; i++) {
            if (live[i] == handle) {
                found = live[i];
                break;
            }
        }
        pthread_mutex_unlock(&registry_lock);
    }
    if (found == NULL && __atomic_fetch_add(&orphan_notes, 1, __ATOMIC_RELAXED) < MAX_ORPHAN_NOTES) {
        fprintf(stderr, "[ftcsim FMU] %s called with %s: refused (no instance to log to)\n", function,
                handle == NULL ? "a NULL instance" : "an instance that is not alive (freed, or never instantiated)");
    }
    return found;
}

static int registry_add(fs_instance *c)
{
    int ok = 1;
    pthread_mutex_lock(&registry_lock);
    if (n_live == cap_live) {
        size_t cap = cap_live ? 2 * cap_live : 16;
        fs_instance **grown = realloc(live, cap * sizeof *grown);
        if (grown == NULL) {
            ok = 0;
        } else {
            live = grown;
            cap_live = cap;
        }
    }
    if (ok) live[n_live++] = c;
    pthread_mutex_unlock(&registry_lock);
    return ok;
}

/* take c out of the registry; its memory goes to the quarantine (the oldest quarantined one is freed) */
static void registry_retire(fs_instance *c)
{
    pthread_mutex_lock(&registry_lock);
    for (size_t i = 0; i < n_live; i++) {
        if (live[i] == c) {
            live[i] = live[--n_live];
            break;
        }
    }
    c->magic = DEAD_MAGIC;
    fs_instance *old = quarantine[quarantine_next];
    quarantine[quarantine_next] = c;
    quarantine_next = (quarantine_next + 1) % QUARANTINE;
    pthread_mutex_unlock(&registry_lock);
    free(old);
}

/* At dlclose and at process exit: only this library's own C memory, each block once. Python objects still
 * held by instances the host never freed are left alone: the interpreter may be finalised already (a Python
 * host exits before the dynamic linker unloads us), and they hold nothing of this library. */
__attribute__((destructor)) static void fs_unload(void)
{
    pthread_mutex_lock(&registry_lock);
    for (size_t i = 0; i < n_live; i++) {
        release_c_memory(live[i]);
        free(live[i]);
    }
    free(live);
    live = NULL;
    n_live = cap_live = 0;
    for (size_t i = 0; i < QUARANTINE; i++) {
        free(quarantine[i]);
        quarantine[i] = NULL;
    }
    pthread_mutex_unlock(&registry_lock);
}

/* -- small helpers --------------------------------------------------------------------------------------- */
static char *dup_string(const char *s)
{
    size_t n = strlen(s);
    char *out = malloc(n + 1);
    if (out) memcpy(out, s, n + 1);
    return out;
}

static char *vformat(const char *fmt, va_list ap)
{
    va_list copy;
    va_copy(copy, ap);
    int n = vsnprintf(NULL, 0, fmt, copy);
    va_end(copy);
    if (n < 0) return NULL;
    char *out = malloc((size_t)n + 1);
    if (out) vsnprintf(out, (size_t)n + 1, fmt, ap);
    return out;
}

const char *fs_mode_name(int mode)
{
    switch (mode) {
    case FS_INSTANTIATED: return "instantiated";
    case FS_CONFIGURATION: return "configuration mode";
    case FS_INIT: return "initialization mode";
    case FS_STEP: return "step mode";
    case FS_TERMINATED: return "terminated";
    case FS_ERRORED: return "error";
    case FS_FATAL_MODE: return "fatal";
    default: return "unknown";
    }
}

static void allowed_names(int allowed, char *out, size_t size)
{
    out[0] = '\0';
    for (int bit = 1; bit <= FS_TERMINATED; bit <<= 1) {
        if (allowed & bit) {
            if (out[0]) strncat(out, ", ", size - strlen(out) - 1);
            strncat(out, fs_mode_name(bit), size - strlen(out) - 1);
        }
    }
}

/* -- logging --------------------------------------------------------------------------------------------- */
static int category_enabled(fs_instance *c, const char *category)
{
    if (c->n_categories == 0) return 1;
    for (size_t i = 0; i < c->n_categories; i++)
        if (category && strcmp(c->categories[i], category) == 0) return 1;
    return 0;
}

static void vlog(fs_instance *c, int status, const char *category, const char *fmt, va_list ap)
{
    /* warnings and errors always reach the host; OK messages only with debug logging on (FMI 2.0 2.1.5,
     * FMI 3.0 2.3.1: loggingOn switches debug logging) */
    if (status < FS_WARNING && !(c->logging_on && category_enabled(c, category))) return;
    char *message = vformat(fmt, ap);
    fs_emit(c, status, category ? category : "", message ? message : "(message could not be formatted)");
    free(message);
}

void fs_log(fs_instance *c, int status, const char *category, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vlog(c, status, category, fmt, ap);
    va_end(ap);
}

static const char *status_category(int status)
{
    switch (status) {
    case FS_WARNING: return "logStatusWarning";
    case FS_DISCARD: return "logStatusDiscard";
    case FS_ERROR: return "logStatusError";
    case FS_FATAL: return "logStatusFatal";
    default: return "logAll";
    }
}

static int python_started_here; /* 1: this library started Python, so the host is not a Python program */

static int vfail(fs_instance *c, int status, const char *fmt, va_list ap)
{
    char *message = vformat(fmt, ap);
    const char *text = message ? message : "(message could not be formatted)";
    fs_emit(c, status, status_category(status), text);
    /* a host that is not a Python program (Ecos's CLI, fmusim, a C master) may show FMU log messages only at a debug
     * level and carry on after an error status: the first error of each instance also goes to stderr, one line */
    if (python_started_here && status >= FS_ERROR && c->error == NULL && c->mode != FS_ERRORED && c->mode != FS_FATAL_MODE)
        fprintf(stderr, "[ftcsim FMU %s] %s: %s\n", c->name ? c->name : "?", status >= FS_FATAL ? "fatal" : "error", text);
    if (status >= FS_FATAL) {
        c->mode = FS_FATAL_MODE;
    } else if (c->mode != FS_FATAL_MODE) {
        c->mode = FS_ERRORED;
    }
    if (c->error == NULL || status >= FS_FATAL) {
        free(c->error);
        c->error = message;
    } else {
        free(message);
    }
    return status;
}

int fs_fail(fs_instance *c, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int out = vfail(c, status, fmt, ap);
    va_end(ap);
    return out;
}

/* refusals logged in full per instance, then in short, then no more (a host that ignores statuses calls on
 * every step: Ecos runs to its stop time) */
#define FULL_REFUSALS 16
#define LOGGED_REFUSALS 1000

static int refuse(fs_instance *c, const char *function, int status)
{
    const char *what = status == FS_FATAL ? "a fatal error" : "an error";
    const char *allowed = status == FS_FATAL ? "freeing the instance" : FS_RECOVERY_CALLS;
    c->refusals++;
    if (c->refusals <= FULL_REFUSALS) {
        fs_log(c, status, status_category(status), "%s: refused: this instance had %s (%s); after it only %s %s allowed",
               function, what, c->error ? c->error : "?", allowed, status == FS_FATAL ? "is" : "are");
    } else if (c->refusals <= LOGGED_REFUSALS) {
        fs_log(c, status, status_category(status), "%s: refused: this instance had %s (see its first message)",
               function, what);
    } else if (c->refusals == LOGGED_REFUSALS + 1) {
        fs_log(c, status, status_category(status), "%s: refused; this instance's further refusals are not logged",
               function);
    }
    return status;
}

int fs_check(fs_instance *c, const char *function, int allowed)
{
    if (c->mode == FS_FATAL_MODE) return refuse(c, function, FS_FATAL);
    if (c->mode == FS_ERRORED && !(allowed & FS_ERRORED)) return refuse(c, function, FS_ERROR);
    if (!Py_IsInitialized()) {
        /* the host's Python has been finalised (a Python host's exit path): neither Python nor the host's logger
         * (it may be a Python function) can be called any more */
        if (c->mode != FS_FATAL_MODE)
            fprintf(stderr, "[ftcsim FMU %s] %s: refused: the host's Python interpreter has been finalised\n",
                    c->name ? c->name : "?", function);
        c->mode = FS_FATAL_MODE;
        return FS_FATAL;
    }
    if (!(c->mode & allowed)) {
        char names[160];
        allowed_names(allowed, names, sizeof names);
        return fs_fail(c, FS_ERROR, "%s: not allowed when the instance is %s (allowed: %s)", function,
                       fs_mode_name(c->mode), names);
    }
    return FS_OK;
}

void fs_set_debug_logging(fs_instance *c, int on, size_t n, const char *const categories[])
{
    for (size_t i = 0; i < c->n_categories; i++) free(c->categories[i]);
    free(c->categories);
    c->categories = NULL;
    c->n_categories = 0;
    c->logging_on = on ? 1 : 0;
    if (n == 0 || categories == NULL) return;
    c->categories = calloc(n, sizeof *c->categories);
    if (c->categories == NULL) return;
    for (size_t i = 0; i < n; i++) {
        if (categories[i] != NULL && (c->categories[c->n_categories] = dup_string(categories[i])) != NULL)
            c->n_categories++;
    }
}

/* -- Python ---------------------------------------------------------------------------------------------- */
static pthread_mutex_t python_lock = PTHREAD_MUTEX_INITIALIZER;
static PyObject *helpers; /* the namespace of HELPERS, per loaded copy of this library; never released */

/* The Python half of the protocol, compiled once per process and library copy. Plain Python objects:
 * nothing in them points into this library, so they outlive a dlclose unharmed. */
static const char HELPERS[] =
    "import importlib, os, sys, traceback\n"
    "\n"
    "def new_instance(cls, resources, name, visible):\n"
    "    obj = cls(instance_name=name, resources=resources, visible=bool(visible), logger=None)\n"
    "    queue = obj._get_log_queue()\n"
    "    if not isinstance(queue, list):\n"
    "        raise TypeError(f'{cls.__name__}._get_log_queue() returned {type(queue).__name__}, not a list')\n"
    "    return obj, queue\n"
    "\n"
    "def new_slave(resources, name, visible, fmi):\n"
    "    listed = os.path.join(resources, 'slavemodule.txt')\n"
    "    try:\n"
    "        with open(listed, encoding='utf-8') as f:\n"
    "            module_name = f.readline().strip()\n"
    "    except (OSError, UnicodeDecodeError) as e:\n"
    "        raise RuntimeError(f'cannot read {listed}: {e}') from None\n"
    "    if not module_name:\n"
    "        raise RuntimeError(f'{listed} names no module')\n"
    "    if resources not in sys.path:  # as pythonfmu: the FMU's own packages are importable\n"
    "        sys.path.insert(0, resources)\n"
    "    module = importlib.import_module(module_name)\n"
    "    bases = ('Fmi2Slave',) if fmi == 2 else ('Fmi3Slave', 'Fmi3SlaveBase')\n"
    "    best = None\n"
    "    for obj in list(vars(module).values()):\n"
    "        if isinstance(obj, type) and obj.__module__ == module.__name__ and any(\n"
    "                b.__name__ in bases for b in obj.__mro__[1:]):\n"
    "            if best is None or len(obj.__mro__) > len(best.__mro__):\n"
    "                best = obj\n"
    "    if best is None:\n"
    "        raise RuntimeError(f'module {module_name} ({getattr(module, \"__file__\", \"?\")}) defines no '\n"
    "                           f'subclass of {bases[0]}')\n"
    "    return (best,) + new_instance(best, resources, name, visible)\n"
    "\n"
    "def describe(exc):\n"
    "    text = f'{type(exc).__name__}: {exc}'\n"
    "    tb = exc.__traceback__\n"
    "    if tb is not None:\n"
    "        frame = traceback.extract_tb(tb)[-1]\n"
    "        text += f' (at {os.path.basename(frame.filename)}:{frame.lineno}, in {frame.name})'\n"
    "    return text\n"
    "\n"
    "def flush():\n"
    "    for stream in (sys.stdout, sys.stderr):\n"
    "        try:\n"
    "            stream.flush()\n"
    "        except Exception:\n"
    "            pass\n";

/* the interpreter is running (started here if the host had none, e.g. a C host with libpython preloaded) */
static int python_ready(char *why, size_t why_size)
{
    if (Py_IsInitialized()) return 1;
    pthread_mutex_lock(&python_lock);
    if (!Py_IsInitialized()) {
        PyConfig config;
        PyConfig_InitPythonConfig(&config);
        config.install_signal_handlers = 0; /* the host's signals stay the host's */
        config.parse_argv = 0;
        PyStatus status = Py_InitializeFromConfig(&config);
        PyConfig_Clear(&config);
        if (PyStatus_Exception(status)) {
            snprintf(why, why_size, "starting the embedded Python failed: %s%s%s (is PYTHONHOME / PYTHONPATH right? "
                     "see `ftcsim host-env`)", status.func ? status.func : "", status.func ? ": " : "",
                     status.err_msg ? status.err_msg : "unknown error");
        } else {
            python_started_here = 1;
            PyEval_SaveThread(); /* every call takes the GIL with PyGILState_Ensure */
        }
    }
    pthread_mutex_unlock(&python_lock);
    return Py_IsInitialized();
}

/* a function of HELPERS (borrowed), or NULL with a Python error set; GIL held */
static PyObject *helper(const char *name)
{
    if (helpers == NULL) {
        PyObject *code = Py_CompileString(HELPERS, "<ftcsim export library>", Py_file_input);
        if (code == NULL) return NULL;
        PyObject *ns = PyDict_New();
        if (ns == NULL || PyDict_SetItemString(ns, "__builtins__", PyEval_GetBuiltins()) != 0) {
            Py_DECREF(code);
            Py_XDECREF(ns);
            return NULL;
        }
        PyObject *done = PyEval_EvalCode(code, ns, ns);
        Py_DECREF(code);
        if (done == NULL) {
            Py_DECREF(ns);
            return NULL;
        }
        Py_DECREF(done);
        helpers = ns;
    }
    PyObject *f = PyDict_GetItemString(helpers, name);
    if (f == NULL) PyErr_Format(PyExc_RuntimeError, "ftcsim export library: no helper %s", name);
    return f;
}

/* The pending Python exception as text (malloc'ed) and its status; clears it. GIL held. */
static char *take_exception(int *status)
{
    PyObject *type = NULL, *value = NULL, *tb = NULL;
    PyErr_Fetch(&type, &value, &tb);
    *status = FS_ERROR;
    if (type == NULL) return dup_string("the call failed without a Python exception");
    PyErr_NormalizeException(&type, &value, &tb);
    if (PyErr_GivenExceptionMatches(type, PyExc_MemoryError) || PyErr_GivenExceptionMatches(type, PyExc_SystemExit) ||
        PyErr_GivenExceptionMatches(type, PyExc_KeyboardInterrupt))
        *status = FS_FATAL;
    if (value != NULL && tb != NULL) PyException_SetTraceback(value, tb);
    char *text = NULL;
    PyObject *describe = value ? helper("describe") : NULL;
    PyObject *described = describe ? PyObject_CallOneArg(describe, value) : NULL;
    if (described == NULL) {
        PyErr_Clear();
        described = PyObject_Str(value ? value : type);
    }
    const char *utf8 = described ? PyUnicode_AsUTF8(described) : NULL;
    if (utf8 != NULL) text = dup_string(utf8);
    PyErr_Clear();
    Py_XDECREF(described);
    Py_XDECREF(type);
    Py_XDECREF(value);
    Py_XDECREF(tb);
    return text ? text : dup_string("a Python exception that cannot be shown");
}

/* log the pending Python exception of `function` and put the instance into error / fatal mode. GIL held. */
static int py_failed(fs_instance *c, const char *function)
{
    int status;
    char *text = take_exception(&status);
    int out = fs_fail(c, status, "%s: %s", function, text ? text : "?");
    free(text);
    return out;
}

/* forward what the slave logged (its log queue, as pythonfmu does) to the host, in the order logged and before
 * the error of the call that logged it. GIL held; a pending Python exception is kept as it is. */
static void drain_log(fs_instance *c)
{
    if (c->queue == NULL || !PyList_Check(c->queue)) return;
    Py_ssize_t n = PyList_GET_SIZE(c->queue);
    if (n == 0) return;
    PyObject *type, *value, *tb;
    PyErr_Fetch(&type, &value, &tb);
    for (Py_ssize_t i = 0; i < n && i < PyList_GET_SIZE(c->queue); i++) {
        PyObject *item = PyList_GET_ITEM(c->queue, i);
        PyObject *status_obj = PyObject_GetAttrString(item, "status");
        PyObject *category_obj = PyObject_GetAttrString(item, "category");
        PyObject *msg_obj = PyObject_GetAttrString(item, "msg");
        long status = status_obj ? PyLong_AsLong(status_obj) : FS_OK;
        if (status < FS_OK || status > FS_FATAL) status = FS_WARNING;
        PyErr_Clear();
        const char *category = category_obj && PyUnicode_Check(category_obj) ? PyUnicode_AsUTF8(category_obj) : NULL;
        PyErr_Clear();
        PyObject *msg_text = msg_obj ? PyObject_Str(msg_obj) : NULL;
        const char *msg = msg_text ? PyUnicode_AsUTF8(msg_text) : NULL;
        PyErr_Clear();
        fs_log(c, (int)status, category ? category : status_category((int)status), "%s",
               msg ? msg : "(a log message that cannot be shown)");
        Py_XDECREF(msg_text);
        Py_XDECREF(status_obj);
        Py_XDECREF(category_obj);
        Py_XDECREF(msg_obj);
    }
    if (PyList_SetSlice(c->queue, 0, PyList_GET_SIZE(c->queue), NULL) != 0) PyErr_Clear();
    PyErr_Restore(type, value, tb);
}

/* -- resources ------------------------------------------------------------------------------------------- */
static int hex_digit(int ch)
{
    if (ch >= '0' && ch <= '9') return ch - '0';
    if (ch >= 'a' && ch <= 'f') return ch - 'a' + 10;
    if (ch >= 'A' && ch <= 'F') return ch - 'A' + 10;
    return -1;
}

/* RFC 3986 2.1 percent-decoding of s; NULL if an escape is malformed or decodes to NUL */
static char *percent_decode(const char *s)
{
    size_t n = strlen(s);
    char *out = malloc(n + 1), *o = out;
    if (out == NULL) return NULL;
    for (size_t i = 0; i < n; i++) {
        if (s[i] != '%') {
            *o++ = s[i];
            continue;
        }
        int hi = i + 1 < n ? hex_digit((unsigned char)s[i + 1]) : -1;
        int lo = i + 2 < n ? hex_digit((unsigned char)s[i + 2]) : -1;
        if (hi < 0 || lo < 0 || (hi == 0 && lo == 0)) {
            free(out);
            return NULL;
        }
        *o++ = (char)(hi * 16 + lo);
        i += 2;
    }
    *o = '\0';
    return out;
}

static int is_folder(char *path)
{
    size_t n = strlen(path);
    while (n > 1 && path[n - 1] == '/') path[--n] = '\0';
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

char *fs_resource_folder(const char *location, char *why, size_t why_size)
{
    if (location == NULL || location[0] == '\0') {
        snprintf(why, why_size, "no resource location given (%s)", location ? "empty" : "NULL");
        return NULL;
    }
    const char *path = NULL;
    int uri = strncasecmp(location, "file:", 5) == 0;
    if (uri) {
        const char *rest = location + 5;
        if (rest[0] == '/' && rest[1] == '/') { /* file://authority/path */
            const char *authority = rest + 2;
            const char *slash = strchr(authority, '/');
            size_t len = slash ? (size_t)(slash - authority) : strlen(authority);
            if (slash == NULL) {
                snprintf(why, why_size, "resource URI '%s' has no path", location);
                return NULL;
            }
            if (len != 0 && !(len == 9 && strncasecmp(authority, "localhost", 9) == 0)) {
                snprintf(why, why_size, "resource URI '%s' names host '%.*s': only local files can be read "
                         "(file:///path or file://localhost/path)", location, (int)len, authority);
                return NULL;
            }
            path = slash;
        } else if (rest[0] == '/') { /* file:/path */
            path = rest;
        } else {
            snprintf(why, why_size, "resource URI '%s' is not absolute (expected file:///path)", location);
            return NULL;
        }
    } else if (location[0] == '/') { /* a plain path (FMI 3.0; also taken from an FMI 2.0 host) */
        path = location;
    } else {
        snprintf(why, why_size, "resource location '%s' is neither a file URI (file:///path) nor an absolute path",
                 location);
        return NULL;
    }
    /* A URI is read percent-decoded; a host that did not encode the path (a '%' that starts no escape, or a
     * folder that exists only as written) is read as written. A plain path is read as it is first. */
    char *decoded = percent_decode(path);
    char *raw = dup_string(path);
    char *first = uri ? decoded : raw, *second = uri ? raw : decoded;
    char *found = NULL;
    if (first && is_folder(first)) {
        found = first;
    } else if (second && is_folder(second)) {
        found = second;
    }
    if (found == NULL) {
        snprintf(why, why_size, "the resource folder %s%s%s does not exist (from resource location '%s')",
                 decoded ? "'" : "", decoded ? decoded : "(malformed percent-escape)", decoded ? "'" : "", location);
    }
    if (decoded != found) free(decoded);
    if (raw != found) free(raw);
    return found;
}

/* The value of attribute `name` in the root element of the modelDescription.xml beside `resources`
 * (malloc'ed), or NULL if there is no such file or attribute. */
static char *model_description_attribute(const char *resources, const char *name)
{
    size_t n = strlen(resources);
    char *path = malloc(n + 32);
    if (path == NULL) return NULL;
    memcpy(path, resources, n + 1);
    char *slash = strrchr(path, '/');
    if (slash == NULL) {
        free(path);
        return NULL;
    }
    strcpy(slash + 1, "modelDescription.xml");
    FILE *f = fopen(path, "rb");
    free(path);
    if (f == NULL) return NULL;
    size_t cap = 1 << 16; /* the root element's attributes come first */
    char *text = malloc(cap + 1);
    size_t got = text ? fread(text, 1, cap, f) : 0;
    fclose(f);
    if (text == NULL) return NULL;
    text[got] = '\0';
    char *out = NULL;
    char *root = strstr(text, "<fmiModelDescription");
    char *end = root ? strchr(root, '>') : NULL;
    if (end != NULL) {
        *end = '\0';
        size_t len = strlen(name);
        for (char *p = root; (p = strstr(p, name)) != NULL; p += len) {
            char before = p[-1];
            char *q = p + len;
            while (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r') q++;
            if ((before != ' ' && before != '\t' && before != '\n' && before != '\r') || *q != '=') continue;
            q++;
            while (*q == ' ' || *q == '\t' || *q == '\n' || *q == '\r') q++;
            char quote = *q;
            if (quote != '"' && quote != '\'') break;
            char *close = strchr(q + 1, quote);
            if (close == NULL) break;
            *close = '\0';
            out = dup_string(q + 1);
            break;
        }
    }
    free(text);
    return out;
}

/* -- life cycle ------------------------------------------------------------------------------------------ */
static void release_c_memory(fs_instance *c)
{
    for (size_t i = 0; i < c->n_categories; i++) free(c->categories[i]);
    free(c->categories);
    c->categories = NULL;
    c->n_categories = 0;
    for (size_t i = 0; i < c->n_strings; i++) free(c->strings[i]);
    free(c->strings);
    c->strings = NULL;
    c->n_strings = 0;
    fs_state *s = c->states;
    while (s != NULL) {
        fs_state *next = s->next;
        s->magic = 0;
        free(s);
        s = next;
    }
    c->states = NULL;
    free(c->name);
    free(c->resources);
    free(c->error);
    c->name = c->resources = c->error = NULL;
}

/* an instance's Python objects, released under the GIL (states' too) */
static void release_python(fs_instance *c)
{
    for (fs_state *s = c->states; s != NULL; s = s->next) {
        Py_CLEAR(s->obj);
        Py_CLEAR(s->bytes);
    }
    Py_CLEAR(c->obj);
    Py_CLEAR(c->queue);
    Py_CLEAR(c->cls);
}

fs_instance *fs_instantiate(int fmi, const char *function, const char *name, const char *token,
                            const char *location, int visible, int logging_on, void *host_env,
                            void (*host_logger)(void))
{
    fs_instance *c = calloc(1, sizeof *c);
    if (c == NULL) return NULL;
    c->magic = LIVE_MAGIC;
    c->fmi = fmi;
    c->mode = FS_INSTANTIATED;
    c->logging_on = logging_on ? 1 : 0;
    c->host_env = host_env;
    c->host_logger = host_logger;
    c->name = dup_string(name ? name : "");
    char why[1024];
    const char *token_name = fmi == 2 ? "guid" : "instantiationToken";
    char *expected = NULL;
    if (c->name == NULL) goto fail_memory;
    if (name == NULL) {
        fs_fail(c, FS_ERROR, "%s: the instance name is NULL", function);
        goto fail;
    }
    c->resources = fs_resource_folder(location, why, sizeof why);
    if (c->resources == NULL) {
        fs_fail(c, FS_ERROR, "%s: %s", function, why);
        goto fail;
    }
    expected = model_description_attribute(c->resources, token_name);
    if (token == NULL || (expected != NULL && strcmp(expected, token) != 0)) {
        fs_fail(c, FS_ERROR, "%s: %s '%s' is not this FMU's ('%s', modelDescription.xml)", function,
                fmi == 2 ? "fmuGUID" : "instantiationToken", token ? token : "(NULL)", expected ? expected : "?");
        goto fail;
    }
    if (!python_ready(why, sizeof why)) {
        fs_fail(c, FS_FATAL, "%s: %s", function, why);
        goto fail;
    }
    PyGILState_STATE gil = PyGILState_Ensure();
    PyObject *made = NULL;
    PyObject *new_slave = helper("new_slave");
    PyObject *resources = PyUnicode_DecodeFSDefault(c->resources);
    PyObject *instance_name = PyUnicode_DecodeUTF8(c->name, (Py_ssize_t)strlen(c->name), "replace");
    if (new_slave && resources && instance_name)
        made = PyObject_CallFunction(new_slave, "OOii", resources, instance_name, visible ? 1 : 0, fmi);
    Py_XDECREF(resources);
    Py_XDECREF(instance_name);
    if (made == NULL || !PyTuple_Check(made) || PyTuple_GET_SIZE(made) != 3) {
        if (made != NULL) PyErr_SetString(PyExc_TypeError, "new_slave returned no (class, instance, queue)");
        Py_XDECREF(made);
        py_failed(c, function);
        PyGILState_Release(gil);
        goto fail;
    }
    c->cls = Py_NewRef(PyTuple_GET_ITEM(made, 0));
    c->obj = Py_NewRef(PyTuple_GET_ITEM(made, 1));
    c->queue = Py_NewRef(PyTuple_GET_ITEM(made, 2));
    Py_DECREF(made);
    drain_log(c);
    PyGILState_Release(gil);
    free(expected);
    if (!registry_add(c)) {
        gil = PyGILState_Ensure();
        release_python(c);
        PyGILState_Release(gil);
        goto fail_memory;
    }
    return c;
fail_memory:
    fprintf(stderr, "[ftcsim FMU] %s: out of memory\n", function);
fail:
    free(expected);
    release_c_memory(c);
    free(c);
    return NULL;
}

void fs_free_instance(void *handle, const char *function)
{
    if (handle == NULL) return; /* FMI 2.0 and 3.0: ignored */
    fs_instance *c = fs_live(handle, function);
    if (c == NULL) return;
    if (Py_IsInitialized()) {
        PyGILState_STATE gil = PyGILState_Ensure();
        drain_log(c);
        release_python(c);
        if (python_started_here) {
            PyObject *flush = helper("flush");
            PyObject *done = flush ? PyObject_CallNoArgs(flush) : NULL;
            Py_XDECREF(done);
        }
        PyErr_Clear();
        PyGILState_Release(gil);
    }
    release_c_memory(c);
    registry_retire(c);
}

int fs_reset(fs_instance *c, const char *function)
{
    PyGILState_STATE gil = PyGILState_Ensure();
    drain_log(c);
    PyObject *new_instance = helper("new_instance");
    PyObject *resources = PyUnicode_DecodeFSDefault(c->resources);
    PyObject *instance_name = PyUnicode_DecodeUTF8(c->name, (Py_ssize_t)strlen(c->name), "replace");
    PyObject *made = NULL;
    if (new_instance && resources && instance_name)
        made = PyObject_CallFunction(new_instance, "OOOi", c->cls, resources, instance_name, 0);
    Py_XDECREF(resources);
    Py_XDECREF(instance_name);
    int status = FS_OK;
    if (made == NULL || !PyTuple_Check(made) || PyTuple_GET_SIZE(made) != 2) {
        if (made != NULL) PyErr_SetString(PyExc_TypeError, "new_instance returned no (instance, queue)");
        Py_XDECREF(made);
        status = py_failed(c, function);
    } else {
        Py_XSETREF(c->obj, Py_NewRef(PyTuple_GET_ITEM(made, 0)));
        Py_XSETREF(c->queue, Py_NewRef(PyTuple_GET_ITEM(made, 1)));
        Py_DECREF(made);
        c->mode = FS_INSTANTIATED;
        c->last_time = 0.0;
        c->terminate_requested = 0;
        free(c->error);
        c->error = NULL;
        c->refusals = 0;
        drain_log(c);
    }
    PyGILState_Release(gil);
    return status;
}

/* -- calls ----------------------------------------------------------------------------------------------- */
int fs_call(fs_instance *c, const char *function, const char *method, int nargs, const double *args,
            unsigned none_mask)
{
    PyGILState_STATE gil = PyGILState_Ensure();
    int status = FS_OK;
    PyObject *tuple = PyTuple_New(nargs);
    for (int i = 0; tuple && i < nargs; i++) {
        PyObject *x = (none_mask >> i) & 1u ? Py_NewRef(Py_None) : PyFloat_FromDouble(args[i]);
        if (x == NULL) Py_CLEAR(tuple);
        else PyTuple_SET_ITEM(tuple, i, x);
    }
    PyObject *bound = tuple ? PyObject_GetAttrString(c->obj, method) : NULL;
    PyObject *r = bound ? PyObject_Call(bound, tuple, NULL) : NULL;
    Py_XDECREF(bound);
    Py_XDECREF(tuple);
    drain_log(c);
    if (r == NULL) status = py_failed(c, function);
    Py_XDECREF(r);
    PyGILState_Release(gil);
    return status;
}

int fs_do_step(fs_instance *c, const char *function, double t, double h, int *terminate)
{
    PyGILState_STATE gil = PyGILState_Ensure();
    int status = FS_OK;
    *terminate = 0;
    PyObject *r = PyObject_CallMethod(c->obj, "do_step", "(dd)", t, h);
    drain_log(c);
    if (r == NULL) {
        status = py_failed(c, function);
    } else {
        PyObject *status_obj = PyObject_HasAttrString(r, "status") ? PyObject_GetAttrString(r, "status") : NULL;
        if (status_obj != NULL) { /* pythonfmu3's Fmi3StepResult */
            long s = PyLong_AsLong(status_obj);
            status = s >= FS_OK && s <= FS_FATAL ? (int)s : FS_ERROR;
            Py_DECREF(status_obj);
            PyObject *stop = PyObject_HasAttrString(r, "terminateSimulation")
                                 ? PyObject_GetAttrString(r, "terminateSimulation") : NULL;
            if (stop != NULL && PyObject_IsTrue(stop) == 1) *terminate = 1;
            Py_XDECREF(stop);
        } else {
            int truth = PyObject_IsTrue(r);
            status = truth == 1 ? FS_OK : truth == 0 ? FS_DISCARD : FS_ERROR;
        }
        PyErr_Clear();
        if (status == FS_DISCARD) {
            *terminate = 1;
            fs_log(c, FS_DISCARD, "logStatusDiscard", "%s(t = %.17g, h = %.17g): the slave's do_step did not complete "
                   "the step", function, t, h);
        } else if (status >= FS_ERROR) {
            fs_fail(c, status, "%s(t = %.17g, h = %.17g): the slave's do_step returned status %d", function, t, h,
                    status);
        }
    }
    Py_XDECREF(r);
    if (status == FS_OK || status == FS_WARNING) {
        c->last_time = t + h;
        c->terminate_requested = *terminate;
    } else if (status == FS_DISCARD) {
        c->terminate_requested = 1;
    }
    PyGILState_Release(gil);
    return status;
}

static PyObject *value_references(const unsigned int *vr, size_t nvr)
{
    PyObject *list = PyList_New((Py_ssize_t)nvr);
    for (size_t i = 0; list && i < nvr; i++) {
        PyObject *x = PyLong_FromUnsignedLong(vr[i]);
        if (x == NULL) Py_CLEAR(list);
        else PyList_SET_ITEM(list, (Py_ssize_t)i, x);
    }
    return list;
}

static void clear_strings(fs_instance *c)
{
    for (size_t i = 0; i < c->n_strings; i++) free(c->strings[i]);
    free(c->strings);
    c->strings = NULL;
    c->n_strings = 0;
}

/* one value returned by the slave into values[i]; 0 with a Python error set on failure */
static int store_value(fs_instance *c, fs_kind kind, PyObject *item, void *values, size_t i)
{
    switch (kind) {
    case FS_REAL: {
        double x = PyFloat_AsDouble(item);
        if (x == -1.0 && PyErr_Occurred()) return 0;
        ((double *)values)[i] = x;
        return 1;
    }
    case FS_INT32: {
        long x = PyLong_AsLong(item);
        if (x == -1 && PyErr_Occurred()) return 0;
        if (x < INT32_MIN || x > INT32_MAX) {
            PyErr_Format(PyExc_OverflowError, "%ld does not fit a 32-bit integer", x);
            return 0;
        }
        ((int32_t *)values)[i] = (int32_t)x;
        return 1;
    }
    case FS_INT64: {
        long long x = PyLong_AsLongLong(item);
        if (x == -1 && PyErr_Occurred()) return 0;
        ((int64_t *)values)[i] = (int64_t)x;
        return 1;
    }
    case FS_UINT64: { /* pythonfmu3 returns ctypes.c_uint64 objects */
        PyObject *v = PyLong_Check(item) ? Py_NewRef(item) : PyObject_GetAttrString(item, "value");
        if (v == NULL) return 0;
        unsigned long long x = PyLong_AsUnsignedLongLong(v);
        Py_DECREF(v);
        if (x == (unsigned long long)-1 && PyErr_Occurred()) return 0;
        ((uint64_t *)values)[i] = (uint64_t)x;
        return 1;
    }
    case FS_BOOL_INT:
    case FS_BOOL_BYTE: {
        int x = PyObject_IsTrue(item);
        if (x < 0) return 0;
        if (kind == FS_BOOL_INT) ((int *)values)[i] = x;
        else ((unsigned char *)values)[i] = (unsigned char)x;
        return 1;
    }
    case FS_STRING: {
        const char *s = PyUnicode_AsUTF8(item);
        if (s == NULL) return 0;
        char *copy = dup_string(s);
        if (copy == NULL) {
            PyErr_NoMemory();
            return 0;
        }
        c->strings[c->n_strings++] = copy;
        ((const char **)values)[i] = copy;
        return 1;
    }
    }
    return 0;
}

int fs_get(fs_instance *c, const char *function, const char *method, fs_kind kind, const unsigned int *vr,
           size_t nvr, void *values, size_t nvalues)
{
    if (nvr == 0) return FS_OK;
    if (vr == NULL || values == NULL)
        return fs_fail(c, FS_ERROR, "%s: %s array is NULL for %zu variables", function,
                       vr == NULL ? "the value-reference" : "the value", nvr);
    if (nvalues < nvr)
        return fs_fail(c, FS_ERROR, "%s: %zu values for %zu value references", function, nvalues, nvr);
    PyGILState_STATE gil = PyGILState_Ensure();
    int status = FS_OK;
    if (kind == FS_STRING) {
        clear_strings(c);
        c->strings = calloc(nvalues, sizeof *c->strings);
    }
    PyObject *refs = value_references(vr, nvr);
    PyObject *r = refs && (kind != FS_STRING || c->strings) ? PyObject_CallMethod(c->obj, method, "(O)", refs) : NULL;
    Py_XDECREF(refs);
    PyObject *seq = r ? PySequence_Fast(r, "the slave's getter returned no sequence") : NULL;
    drain_log(c);
    if (seq == NULL) {
        status = py_failed(c, function);
    } else if ((size_t)PySequence_Fast_GET_SIZE(seq) != nvalues) {
        status = fs_fail(c, FS_ERROR, "%s: the slave's %s returned %zd values for %zu", function, method,
                         PySequence_Fast_GET_SIZE(seq), nvalues);
    } else {
        PyObject **items = PySequence_Fast_ITEMS(seq);
        for (size_t i = 0; i < nvalues; i++) {
            if (!store_value(c, kind, items[i], values, i)) {
                char prefix[200];
                snprintf(prefix, sizeof prefix, "%s: value %zu from the slave's %s", function, i, method);
                status = py_failed(c, prefix);
                break;
            }
        }
    }
    Py_XDECREF(seq);
    Py_XDECREF(r);
    PyGILState_Release(gil);
    return status;
}

static PyObject *make_value(fs_kind kind, const void *values, size_t i)
{
    switch (kind) {
    case FS_REAL: return PyFloat_FromDouble(((const double *)values)[i]);
    case FS_INT32: return PyLong_FromLong(((const int32_t *)values)[i]);
    case FS_INT64: return PyLong_FromLongLong(((const int64_t *)values)[i]);
    case FS_UINT64: return PyLong_FromUnsignedLongLong(((const uint64_t *)values)[i]);
    case FS_BOOL_INT: return PyBool_FromLong(((const int *)values)[i] != 0);
    case FS_BOOL_BYTE: return PyBool_FromLong(((const unsigned char *)values)[i] != 0);
    case FS_STRING: {
        const char *s = ((const char *const *)values)[i];
        if (s == NULL) {
            PyErr_Format(PyExc_ValueError, "string value %zu is NULL", i);
            return NULL;
        }
        return PyUnicode_DecodeUTF8(s, (Py_ssize_t)strlen(s), "strict");
    }
    }
    return NULL;
}

int fs_set(fs_instance *c, const char *function, const char *method, fs_kind kind, const unsigned int *vr,
           size_t nvr, const void *values, size_t nvalues)
{
    if (nvr == 0) return FS_OK;
    if (vr == NULL || values == NULL)
        return fs_fail(c, FS_ERROR, "%s: %s array is NULL for %zu variables", function,
                       vr == NULL ? "the value-reference" : "the value", nvr);
    if (nvalues < nvr)
        return fs_fail(c, FS_ERROR, "%s: %zu values for %zu value references", function, nvalues, nvr);
    PyGILState_STATE gil = PyGILState_Ensure();
    PyObject *refs = value_references(vr, nvr);
    PyObject *list = PyList_New((Py_ssize_t)nvalues);
    for (size_t i = 0; list && i < nvalues; i++) {
        PyObject *x = make_value(kind, values, i);
        if (x == NULL) Py_CLEAR(list);
        else PyList_SET_ITEM(list, (Py_ssize_t)i, x);
    }
    PyObject *r = refs && list ? PyObject_CallMethod(c->obj, method, "(OO)", refs, list) : NULL;
    Py_XDECREF(refs);
    Py_XDECREF(list);
    drain_log(c);
    int status = r == NULL ? py_failed(c, function) : FS_OK;
    Py_XDECREF(r);
    PyGILState_Release(gil);
    return status;
}

/* -- FMU state ------------------------------------------------------------------------------------------- */
fs_state *fs_state_of(fs_instance *c, void *handle)
{
    if (handle == NULL) return NULL;
    for (fs_state *s = c->states; s != NULL; s = s->next)
        if (s == handle) return s;
    return NULL;
}

static fs_state *new_state(fs_instance *c)
{
    fs_state *s = calloc(1, sizeof *s);
    if (s == NULL) return NULL;
    s->magic = STATE_MAGIC;
    s->owner = c;
    s->next = c->states;
    c->states = s;
    return s;
}

int fs_get_state(fs_instance *c, const char *function, void **inout)
{
    if (inout == NULL) return fs_fail(c, FS_ERROR, "%s: the FMU state pointer is NULL", function);
    PyGILState_STATE gil = PyGILState_Ensure();
    int status = FS_OK;
    PyObject *r = PyObject_CallMethod(c->obj, "_get_fmu_state", NULL);
    drain_log(c);
    if (r == NULL) {
        status = py_failed(c, function);
    } else {
        /* FMI: a non-NULL *state is a state of this instance to overwrite; an unknown pointer is never
         * dereferenced (a new state is made instead) */
        fs_state *s = fs_state_of(c, *inout);
        if (s == NULL) s = new_state(c);
        if (s == NULL) {
            Py_DECREF(r);
            status = fs_fail(c, FS_ERROR, "%s: out of memory", function);
        } else {
            Py_XSETREF(s->obj, r);
            Py_CLEAR(s->bytes);
            s->mode = c->mode;
            s->last_time = c->last_time;
            s->terminate_requested = c->terminate_requested;
            *inout = s;
        }
    }
    PyGILState_Release(gil);
    return status;
}

int fs_set_state(fs_instance *c, const char *function, void *handle)
{
    fs_state *s = fs_state_of(c, handle);
    if (s == NULL || s->obj == NULL)
        return fs_fail(c, FS_ERROR, "%s: %s is not an FMU state of this instance", function,
                       handle == NULL ? "NULL" : "the pointer given");
    PyGILState_STATE gil = PyGILState_Ensure();
    PyObject *r = PyObject_CallMethod(c->obj, "_set_fmu_state", "(O)", s->obj);
    drain_log(c);
    int status = FS_OK;
    if (r == NULL) {
        status = py_failed(c, function);
    } else {
        Py_DECREF(r);
        c->mode = s->mode;
        c->last_time = s->last_time;
        c->terminate_requested = s->terminate_requested;
        free(c->error);
        c->error = NULL;
        c->refusals = 0;
    }
    PyGILState_Release(gil);
    return status;
}

int fs_free_state(fs_instance *c, const char *function, void **inout)
{
    if (inout == NULL) return fs_fail(c, FS_ERROR, "%s: the FMU state pointer is NULL", function);
    if (*inout == NULL) return FS_OK; /* FMI: ignored */
    fs_state *s = fs_state_of(c, *inout);
    if (s == NULL) return fs_fail(c, FS_ERROR, "%s: the pointer given is not an FMU state of this instance", function);
    fs_state **link = &c->states;
    while (*link != s) link = &(*link)->next;
    *link = s->next;
    PyGILState_STATE gil = PyGILState_Ensure();
    Py_CLEAR(s->obj);
    Py_CLEAR(s->bytes);
    PyGILState_Release(gil);
    s->magic = 0;
    free(s);
    *inout = NULL;
    return FS_OK;
}

/* the slave's serialisation of state s, kept in s->bytes; GIL held; 0 with a Python error on failure */
static int state_bytes(fs_instance *c, fs_state *s)
{
    if (s->bytes != NULL) return 1;
    PyObject *r = PyObject_CallMethod(c->cls, "_fmu_state_to_bytes", "(O)", s->obj);
    if (r == NULL) return 0;
    if (!PyBytes_Check(r)) {
        PyErr_Format(PyExc_TypeError, "_fmu_state_to_bytes returned %s, not bytes", Py_TYPE(r)->tp_name);
        Py_DECREF(r);
        return 0;
    }
    s->bytes = r;
    return 1;
}

int fs_state_size(fs_instance *c, const char *function, void *handle, size_t *size)
{
    fs_state *s = fs_state_of(c, handle);
    if (s == NULL || s->obj == NULL || size == NULL)
        return fs_fail(c, FS_ERROR, "%s: %s", function, size == NULL ? "the size pointer is NULL"
                                                                      : "not an FMU state of this instance");
    PyGILState_STATE gil = PyGILState_Ensure();
    int status = FS_OK;
    if (!state_bytes(c, s)) status = py_failed(c, function);
    else *size = SERIAL_HEADER + (size_t)PyBytes_GET_SIZE(s->bytes);
    PyGILState_Release(gil);
    return status;
}

int fs_serialize_state(fs_instance *c, const char *function, void *handle, unsigned char *bytes, size_t size)
{
    fs_state *s = fs_state_of(c, handle);
    if (s == NULL || s->obj == NULL) return fs_fail(c, FS_ERROR, "%s: not an FMU state of this instance", function);
    if (bytes == NULL) return fs_fail(c, FS_ERROR, "%s: the byte array is NULL", function);
    PyGILState_STATE gil = PyGILState_Ensure();
    int status = FS_OK;
    if (!state_bytes(c, s)) {
        status = py_failed(c, function);
    } else {
        size_t need = SERIAL_HEADER + (size_t)PyBytes_GET_SIZE(s->bytes);
        if (size < need) {
            status = fs_fail(c, FS_ERROR, "%s: %zu bytes given, the state needs %zu (the serialized-state size)",
                             function, size, need);
        } else {
            int32_t mode = s->mode, stop = s->terminate_requested;
            memcpy(bytes, SERIAL_MAGIC, 8);
            memcpy(bytes + 8, &mode, 4);
            memcpy(bytes + 12, &stop, 4);
            memcpy(bytes + 16, &s->last_time, 8);
            memcpy(bytes + SERIAL_HEADER, PyBytes_AS_STRING(s->bytes), need - SERIAL_HEADER);
        }
    }
    PyGILState_Release(gil);
    return status;
}

int fs_deserialize_state(fs_instance *c, const char *function, const unsigned char *bytes, size_t size, void **out)
{
    if (out == NULL) return fs_fail(c, FS_ERROR, "%s: the FMU state pointer is NULL", function);
    if (bytes == NULL || size < SERIAL_HEADER || memcmp(bytes, SERIAL_MAGIC, 8) != 0)
        return fs_fail(c, FS_ERROR, "%s: the %zu bytes given are not an FMU state serialized by this FMU", function,
                       bytes == NULL ? (size_t)0 : size);
    int32_t mode, stop;
    double last_time;
    memcpy(&mode, bytes + 8, 4);
    memcpy(&stop, bytes + 12, 4);
    memcpy(&last_time, bytes + 16, 8);
    if (!(mode == FS_INSTANTIATED || mode == FS_CONFIGURATION || mode == FS_INIT || mode == FS_STEP ||
          mode == FS_TERMINATED))
        return fs_fail(c, FS_ERROR, "%s: the serialized state names no valid mode (%d)", function, (int)mode);
    PyGILState_STATE gil = PyGILState_Ensure();
    int status = FS_OK;
    PyObject *payload = PyBytes_FromStringAndSize((const char *)bytes + SERIAL_HEADER,
                                                  (Py_ssize_t)(size - SERIAL_HEADER));
    PyObject *r = payload ? PyObject_CallMethod(c->cls, "_fmu_state_from_bytes", "(O)", payload) : NULL;
    Py_XDECREF(payload);
    drain_log(c);
    if (r == NULL) {
        status = py_failed(c, function);
    } else {
        fs_state *s = new_state(c); /* *out is not read: hosts pass uninitialised variables */
        if (s == NULL) {
            Py_DECREF(r);
            status = fs_fail(c, FS_ERROR, "%s: out of memory", function);
        } else {
            s->obj = r;
            s->mode = mode;
            s->terminate_requested = stop != 0;
            s->last_time = last_time;
            *out = s;
        }
    }
    PyGILState_Release(gil);
    return status;
}
