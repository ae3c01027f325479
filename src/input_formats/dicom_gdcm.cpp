/* SPDX-License-Identifier: BSD-3-Clause */
// DICOM files through GDCM: the header fields DICOM input needs, and one file's pixels decoded
// into a caller's buffer. The only C++ of the library: every call is inside try/catch, and
// only plain C values cross dicom_gdcm.h.
#include "dicom_gdcm.h"

#include <gdcmException.h>
#include <gdcmImage.h>
#include <gdcmImageReader.h>
#include <gdcmJPEG2000Codec.h>
#include <gdcmJPEGCodec.h>
#include <gdcmJPEGLSCodec.h>
#include <gdcmRAWCodec.h>
#include <gdcmRLECodec.h>
#include <gdcmReader.h>
#include <gdcmStringFilter.h>
#include <gdcmTrace.h>
#include <gdcmTransferSyntax.h>

#include <cstdio>
#include <cstring>
#include <string>

namespace
{

// The library reports its own warnings on std::cerr unless told not to; this library never
// prints. Done once (a function-local static is initialised exactly once, thread-safely).
void keep_quiet()
{
    static const bool quiet = [] {
        gdcm::Trace::SetDebug(false);
        gdcm::Trace::SetWarning(false);
        gdcm::Trace::SetError(false);
        return true;
    }();
    (void)quiet;
}

// The reason into why[size], on one line (what GDCM's exceptions say holds line breaks).
void say(char *why, size_t size, const char *text)
{
    if (size == 0)
        return;
    std::snprintf(why, size, "%s", text);
    for (char *c = why; *c; c++)
        if (static_cast<unsigned char>(*c) < 0x20 || *c == 0x7F)
            *c = ' ';
}

// `text` without the trailing spaces and NULs that pad DICOM values to an even length.
void store_value(const std::string &text, char out[IP_DICOM_VALUE_MAX])
{
    size_t end = text.size();
    while (end > 0 && (text[end - 1] == ' ' || text[end - 1] == '\0'))
        end--;
    size_t begin = 0;
    while (begin < end && text[begin] == ' ')
        begin++;
    size_t length = end - begin < IP_DICOM_VALUE_MAX - 1 ? end - begin : IP_DICOM_VALUE_MAX - 1;
    std::memcpy(out, text.data() + begin, length);
    out[length] = '\0';
}

struct field_tag {
    ip_dicom_field field;
    unsigned short group, element;
};

const field_tag dataset_fields[] = {
    {IP_DICOM_MODALITY, 0x0008, 0x0060},
    {IP_DICOM_SERIES_DESCRIPTION, 0x0008, 0x103E},
    {IP_DICOM_SERIES_UID, 0x0020, 0x000E},
    {IP_DICOM_POSITION, 0x0020, 0x0032},
    {IP_DICOM_ORIENTATION, 0x0020, 0x0037},
    {IP_DICOM_SAMPLES_PER_PIXEL, 0x0028, 0x0002},
    {IP_DICOM_PHOTOMETRIC, 0x0028, 0x0004},
    {IP_DICOM_FRAMES, 0x0028, 0x0008},
    {IP_DICOM_ROWS, 0x0028, 0x0010},
    {IP_DICOM_COLUMNS, 0x0028, 0x0011},
    {IP_DICOM_PIXEL_SPACING, 0x0028, 0x0030},
    {IP_DICOM_BITS_ALLOCATED, 0x0028, 0x0100},
    {IP_DICOM_BITS_STORED, 0x0028, 0x0101},
    {IP_DICOM_HIGH_BIT, 0x0028, 0x0102},
    {IP_DICOM_PIXEL_REPRESENTATION, 0x0028, 0x0103},
    {IP_DICOM_RESCALE_INTERCEPT, 0x0028, 0x1052},
    {IP_DICOM_RESCALE_SLOPE, 0x0028, 0x1053},
    {IP_DICOM_RESCALE_TYPE, 0x0028, 0x1054},
};

// The transfer syntax as the file's meta header spells it, whether the library knows it or not.
std::string syntax_uid(const gdcm::File &file)
{
    const gdcm::Tag tag(0x0002, 0x0010);
    const gdcm::FileMetaInformation &meta = file.GetHeader();
    if (!meta.FindDataElement(tag))
        return std::string();
    const gdcm::ByteValue *bytes = meta.GetDataElement(tag).GetByteValue();
    return bytes ? std::string(bytes->GetPointer(), bytes->GetLength()) : std::string();
}

bool decodable(const gdcm::TransferSyntax &ts)
{
    return gdcm::RAWCodec().CanDecode(ts) || gdcm::RLECodec().CanDecode(ts) ||
           gdcm::JPEGCodec().CanDecode(ts) || gdcm::JPEGLSCodec().CanDecode(ts) ||
           gdcm::JPEG2000Codec().CanDecode(ts);
}

void fill_syntax(const gdcm::File &file, ip_dicom_header *out)
{
    store_value(syntax_uid(file), out->value[IP_DICOM_TRANSFER_SYNTAX]);
    gdcm::TransferSyntax::TSType type =
        gdcm::TransferSyntax::GetTSType(out->value[IP_DICOM_TRANSFER_SYNTAX]);
    gdcm::TransferSyntax ts(type);
    out->syntax_known = ts.IsValid() ? 1 : 0;
    out->syntax_decodable = out->syntax_known && decodable(ts) ? 1 : 0;
    if (ts.IsValid())
        store_value(gdcm::TransferSyntax::GetTSString(type), out->syntax_name);
}

void fill_header(const gdcm::File &file, ip_dicom_header *out)
{
    gdcm::StringFilter filter;
    filter.SetFile(file);
    const gdcm::DataSet &ds = file.GetDataSet();
    for (const field_tag &f : dataset_fields) {
        const gdcm::Tag tag(f.group, f.element);
        if (ds.FindDataElement(tag) && !ds.GetDataElement(tag).IsEmpty())
            store_value(filter.ToString(tag), out->value[f.field]);
    }
    fill_syntax(file, out);
}

// The reason a file failed, or nullptr: the work of ip__dicom_read_header().
const char *read_header(const char *path, ip_dicom_header *out)
{
    std::memset(out, 0, sizeof *out);
    gdcm::Reader reader;
    reader.SetFileName(path);
    if (!reader.ReadUpToTag(gdcm::Tag(0x7FE0, 0x0010))) {
        // A transfer syntax the library does not know stops it after the meta header: that
        // syntax is the reason to report, which the caller does from the fields.
        fill_syntax(reader.GetFile(), out);
        if (out->value[IP_DICOM_TRANSFER_SYNTAX][0] != '\0' && !out->syntax_known)
            return nullptr;
        return "not a readable DICOM file";
    }
    fill_header(reader.GetFile(), out);
    return nullptr;
}

void describe_image(const gdcm::Image &image, ip_dicom_image *out)
{
    const gdcm::PixelFormat &format = image.GetPixelFormat();
    out->columns = image.GetDimension(0);
    out->rows = image.GetDimension(1);
    out->frames = image.GetNumberOfDimensions() > 2 ? image.GetDimension(2) : 1;
    out->bits_allocated = format.GetBitsAllocated();
    out->samples_per_pixel = format.GetSamplesPerPixel();
    out->is_signed = format.GetPixelRepresentation() ? 1 : 0;
    out->bytes = image.GetBufferLength();
}

// The reason a file failed, or nullptr: the work of ip__dicom_decode().
const char *decode(const char *path, void *dst, size_t capacity, ip_dicom_image *image)
{
    std::memset(image, 0, sizeof *image);
    gdcm::ImageReader reader;
    reader.SetFileName(path);
    if (!reader.Read())
        return "not a readable DICOM image";
    const gdcm::Image &decoded = reader.GetImage();
    describe_image(decoded, image);
    if (image->bytes > capacity)
        return "the image is larger than a plane";
    if (!decoded.GetBuffer(static_cast<char *>(dst)))
        return "its pixel data do not decode";
    return nullptr;
}

// Runs `work` (returning a reason or nullptr) with nothing thrown escaping: 0, or -1 with the
// reason, or the exception's message, in why.
template <typename Work> int guarded(Work work, char *why, size_t why_size)
{
    try {
        keep_quiet();
        const char *reason = work();
        if (!reason)
            return 0;
        say(why, why_size, reason);
    } catch (const gdcm::Exception &e) {
        say(why, why_size, e.GetDescription()); // what() adds GDCM's source file and line
    } catch (const std::exception &e) {
        say(why, why_size, e.what());
    } catch (...) {
        say(why, why_size, "the DICOM library failed");
    }
    return -1;
}

} // namespace

extern "C" int ip__dicom_read_header(const char *path, ip_dicom_header *out, char *why,
                                     size_t why_size)
{
    return guarded([=] { return read_header(path, out); }, why, why_size);
}

extern "C" int ip__dicom_decode(const char *path, void *dst, size_t capacity, ip_dicom_image *image,
                                char *why, size_t why_size)
{
    return guarded([=] { return decode(path, dst, capacity, image); }, why, why_size);
}
