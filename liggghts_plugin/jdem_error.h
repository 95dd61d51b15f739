/* jdem_error.h — liggghts-jdem's own Error::all, Error::one, Error::fix_error and
 * Error::compute_error.  libliggghts calls them through its PLT, so these definitions in the
 * executable replace the library's for LIGGGHTS' errors and ours alike (the mechanism of
 * Output::add_dump in main.cpp).  They print the library's text ("ERROR: MSG (FILE:LINE)",
 * "ERROR on proc N: MSG (FILE:LINE)") to the screen, to the log and to stderr, flushed, then end
 * the run as the library does (exit status 1).  What they fix:
 *   - Error::one ends in MPI_Abort, which does not flush stdio: on a pipe (and with -screen none
 *     always) the message was lost, and it never reached the log;
 *   - Debian's build prints after every error a second "special message" line that is a
 *     dangling string: garbage bytes. */
#ifndef JDEM_ERROR_H
#define JDEM_ERROR_H

/* The log file's name (the -log argument; NULL or "none": no log), for ranks > 0, which hold
 * no log stream: their Error::one appends its line to that file. */
void jdem_error_log_path(const char *path);

#endif
