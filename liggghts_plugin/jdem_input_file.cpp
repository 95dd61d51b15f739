/* jdem_input_file.cpp — see jdem_input_file.h. */
#include "jdem_input_file.h"

#include <mpi.h>

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>

#include "error.h"
#include "lammps.h"

static std::string named(const char *what, const char *path, const std::string &reason) {
  return std::string(what) + " " + path + ": " + reason;
}

std::string jdem_open_input(const char *what, const char *path, std::ifstream &in) {
  struct stat st;
  if (stat(path, &st) != 0) return named(what, path, std::strerror(errno));
  if (S_ISDIR(st.st_mode)) return named(what, path, "is a directory, not a file");
  if (!S_ISREG(st.st_mode))
    return named(what, path, "is not a regular file (a device, FIFO or socket); give a text file");
  if (st.st_size == 0) return named(what, path, "is empty");
  if (st.st_size > JDEM_INPUT_MAX_BYTES) {
    char bound[96];
    std::snprintf(bound, sizeof bound, "is %lld bytes, more than the bound of %lld", (long long)st.st_size,
                  JDEM_INPUT_MAX_BYTES);
    return named(what, path, bound);
  }
  in.open(path);
  if (!in) return named(what, path, std::string("cannot be opened: ") + std::strerror(errno));
  return "";
}

std::string jdem_text_line(const char *what, const char *path, int lineno, const std::string &line) {
  for (size_t k = 0; k < line.size(); k++) {
    const unsigned char c = (unsigned char)line[k];
    if ((c < 0x20 && c != '\t' && c != '\r') || c == 0x7f) {
      char where[96];
      std::snprintf(where, sizeof where, " line %d: binary data (byte 0x%02x); expected text", lineno, c);
      return std::string(what) + " " + path + where;
    }
  }
  return "";
}

namespace {

template <typename T>
void share_rows(LAMMPS_NS::LAMMPS *lmp, int bad, char *msg, size_t msglen, std::vector<T> &rows,
                MPI_Datatype type) {
  MPI_Comm world = lmp->world;
  MPI_Bcast(&bad, 1, MPI_INT, 0, world);
  if (bad) {
    MPI_Bcast(msg, (int)msglen, MPI_CHAR, 0, world);
    lmp->error->all(FLERR, msg);
  }
  int n = (int)rows.size();
  MPI_Bcast(&n, 1, MPI_INT, 0, world);
  rows.resize(n);
  if (n) MPI_Bcast(rows.data(), n, type, 0, world);
}

}  // namespace

void jdem_share_input(LAMMPS_NS::LAMMPS *lmp, int bad, char *msg, size_t msglen,
                      std::vector<double> &rows) {
  share_rows(lmp, bad, msg, msglen, rows, MPI_DOUBLE);
}

void jdem_share_input(LAMMPS_NS::LAMMPS *lmp, int bad, char *msg, size_t msglen,
                      std::vector<int> &rows) {
  share_rows(lmp, bad, msg, msglen, rows, MPI_INT);
}
