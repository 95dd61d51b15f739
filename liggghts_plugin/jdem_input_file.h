/* jdem_input_file.h — the text files our styles read (fix bond/jiang file, fix jdem/loads file,
 * dump h5md/jdem scene_yaml): what a file must be before a style reads it, with one message
 * naming the file for everything else (a directory, a device such as /dev/zero, a FIFO, an
 * empty file, binary data, a file beyond the size bound). */
#ifndef JDEM_INPUT_FILE_H
#define JDEM_INPUT_FILE_H

#include <cstddef>
#include <fstream>
#include <string>
#include <vector>

namespace LAMMPS_NS {
class LAMMPS;
}

/* Largest input file [bytes]: 1 GiB, tens of millions of bonds or loads (the readers hold it on
 * rank 0 before broadcasting it). */
const long long JDEM_INPUT_MAX_BYTES = 1LL << 30;

/* Open PATH for reading as the input WHAT (e.g. "fix bond/jiang: bond file"): a regular,
 * non-empty file of at most JDEM_INPUT_MAX_BYTES.  Returns "" with IN open, or the message
 * "WHAT PATH: <reason>" (IN then unusable). */
std::string jdem_open_input(const char *what, const char *path, std::ifstream &in);

/* "" for a line of text, else the message "WHAT PATH line N: binary data (byte 0xXX)": a NUL or
 * another control character other than tab and carriage return. */
std::string jdem_text_line(const char *what, const char *path, int lineno, const std::string &line);

/* Collective: rank 0's verdict on the file it read and, when it is good, its rows on every rank.
 * BAD and MSG (MSGLEN bytes) are rank 0's; when BAD, every rank stops with error->all(MSG), else
 * ROWS becomes rank 0's rows everywhere. */
void jdem_share_input(LAMMPS_NS::LAMMPS *lmp, int bad, char *msg, size_t msglen,
                      std::vector<double> &rows);
void jdem_share_input(LAMMPS_NS::LAMMPS *lmp, int bad, char *msg, size_t msglen,
                      std::vector<int> &rows);

#endif
