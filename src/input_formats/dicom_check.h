/* SPDX-License-Identifier: BSD-3-Clause */
/* A DICOM Part 10 file's structure checked before the DICOM library parses it: every element's
 * length within the file, sequences and items closed, and the Pixel Data as long as the image
 * its header describes. The library (GDCM) stops the process on some truncated files and reads
 * past its buffer on a short Pixel Data element; what passes this check it parses safely.
 * Internal to the input module. */
#ifndef ISOPROP_DICOM_CHECK_H
#define ISOPROP_DICOM_CHECK_H

#include <stddef.h>

/* Checks the file at `path` (a Part 10 file: 128-byte preamble, "DICM", the meta group in
 * explicit VR little endian, then the data set in the transfer syntax's encoding; a deflated
 * data set is not walked). Returns 0, or -1 with the reason (one line, without the path) in
 * why[0 .. why_size). */
int ip__dicom_check_file(const char *path, char *why, size_t why_size);

/* ip__dicom_check_file(), and the SOP class the file names into sop_class (passed or not): its
 * data set's SOP Class UID (0008,0016) when the check walked past it, else its meta header's
 * Media Storage SOP Class UID (0002,0002) when the meta header is well formed, else "". So a
 * DICOM object that is not an image (no Pixel Data, or a structure the check refuses) can be
 * told apart from a broken image. */
int ip__dicom_check_object(const char *path, char sop_class[65], char *why, size_t why_size);

#endif
