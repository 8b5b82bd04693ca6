/* png_write.h - a minimal PNG writer for the radiosity.h examples. Public domain or MIT.

   Writes 8-bit RGB images. The pixel data goes into "stored" (uncompressed) deflate blocks
   inside a zlib stream, so the file is about 3 bytes per pixel, but the writer is short,
   has no dependencies and is easy to check against the PNG specification (RFC 2083) and the
   zlib/deflate formats (RFC 1950, RFC 1951):

       signature | IHDR | IDAT (zlib: header, stored blocks, Adler-32) | IEND

   every chunk being length (big-endian) | type | data | CRC-32 of type and data.

   Usage (all functions are static; include it in any number of files):

       #include "png_write.h"
       int ok = png_write_rgb8("out.png", width, height, pixels, width * 3) == 0;

   'pixels' holds rows top to bottom, 3 bytes (r g b) per pixel, 'stride' bytes apart. */

#ifndef PNG_WRITE_H
#define PNG_WRITE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#if defined(__GNUC__) || defined(__clang__)
#  define PNGW__UNUSED __attribute__((unused))
#else
#  define PNGW__UNUSED
#endif

/* CRC-32 of RFC 2083 / ISO 3309 (reflected polynomial 0xEDB88320), continued from 'crc'
   (start with 0). The table is built on first use. */
static uint32_t pngw__crc32(uint32_t crc, const unsigned char *data, size_t size)
{
    static uint32_t table[256];
    static int table_ready = 0;
    size_t i;
    if (!table_ready) {
        uint32_t n, k, c;
        for (n = 0; n < 256; ++n) {
            c = n;
            for (k = 0; k < 8; ++k) c = (c & 1u) ? (0xEDB88320u ^ (c >> 1)) : (c >> 1);
            table[n] = c;
        }
        table_ready = 1;
    }
    crc = ~crc;
    for (i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFFu] ^ (crc >> 8);
    return ~crc;
}

/* Adler-32 of RFC 1950, continued from 'adler' (start with 1). */
static uint32_t pngw__adler32(uint32_t adler, const unsigned char *data, size_t size)
{
    uint32_t a = adler & 0xFFFFu, b = adler >> 16;
    while (size > 0) {
        /* 5552 is the largest run for which b cannot overflow 32 bits before the modulo */
        size_t run = size < 5552 ? size : 5552, i;
        for (i = 0; i < run; ++i) {
            a += data[i];
            b += a;
        }
        a %= 65521u;
        b %= 65521u;
        data += run;
        size -= run;
    }
    return (b << 16) | a;
}

static void pngw__put32(unsigned char *p, uint32_t v)
{
    p[0] = (unsigned char)(v >> 24);
    p[1] = (unsigned char)(v >> 16);
    p[2] = (unsigned char)(v >> 8);
    p[3] = (unsigned char)v;
}

/* Writes one chunk: length, type, data, CRC over type and data. Returns 0 or -1. */
static int pngw__chunk(FILE *f, const char type[4], const unsigned char *data, uint32_t size)
{
    unsigned char head[8], tail[4];
    uint32_t crc;
    pngw__put32(head, size);
    memcpy(head + 4, type, 4);
    crc = pngw__crc32(0, head + 4, 4);
    crc = pngw__crc32(crc, data, size);
    pngw__put32(tail, crc);
    if (fwrite(head, 1, 8, f) != 8) return -1;
    if (size > 0 && fwrite(data, 1, size, f) != size) return -1;
    if (fwrite(tail, 1, 4, f) != 4) return -1;
    return 0;
}

/* Writes an 8-bit RGB PNG. Returns 0 on success, -1 on a bad argument, an image too large
   for one IDAT chunk, an allocation failure or an I/O error. */
static PNGW__UNUSED int png_write_rgb8(const char *path, uint32_t width, uint32_t height,
                                       const unsigned char *rgb, size_t stride)
{
    static const unsigned char signature[8] = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n' };
    unsigned char ihdr[13];
    unsigned char *raw, *z, *p;
    size_t row_bytes, raw_size, blocks, z_size, off, y;
    uint32_t adler;
    FILE *f;
    int status = 0;

    if (!path || !rgb || width == 0 || height == 0 || width > 0x7FFFFFFFu / 3u || stride < 3u * (size_t)width)
        return -1;
    row_bytes = 1 + 3 * (size_t)width; /* filter byte 0 (None), then the pixels */
    if ((size_t)height > ((size_t)0x7FFFFFFF - 64) / row_bytes) return -1;
    raw_size = row_bytes * height;
    blocks = (raw_size + 65534) / 65535;                 /* stored blocks hold <= 65535 bytes */
    z_size = 2 + raw_size + 5 * blocks + 4;              /* zlib header, blocks, Adler-32 */
    if (z_size > 0x7FFFFFFFu) return -1;

    raw = (unsigned char *)malloc(raw_size);
    z = (unsigned char *)malloc(z_size);
    if (!raw || !z) {
        free(raw);
        free(z);
        return -1;
    }
    for (y = 0; y < height; ++y) {
        raw[y * row_bytes] = 0;
        memcpy(raw + y * row_bytes + 1, rgb + y * stride, 3 * (size_t)width);
    }

    /* zlib stream: CMF 0x78 (deflate, 32K window), FLG 0x01 (0x7801 % 31 == 0, no dictionary,
       "fastest" level), stored blocks, Adler-32 of the uncompressed data, big-endian. */
    p = z;
    *p++ = 0x78;
    *p++ = 0x01;
    for (off = 0; off < raw_size;) {
        size_t n = raw_size - off < 65535 ? raw_size - off : 65535;
        int last = off + n == raw_size;
        *p++ = (unsigned char)(last ? 1 : 0);           /* BFINAL, BTYPE = 00 (stored) */
        *p++ = (unsigned char)(n & 0xFFu);               /* LEN, little-endian */
        *p++ = (unsigned char)(n >> 8);
        *p++ = (unsigned char)(~n & 0xFFu);              /* NLEN = ~LEN */
        *p++ = (unsigned char)((~n >> 8) & 0xFFu);
        memcpy(p, raw + off, n);
        p += n;
        off += n;
    }
    adler = pngw__adler32(1, raw, raw_size);
    pngw__put32(p, adler);
    p += 4;

    pngw__put32(ihdr, width);
    pngw__put32(ihdr + 4, height);
    ihdr[8] = 8;   /* bit depth */
    ihdr[9] = 2;   /* colour type: RGB */
    ihdr[10] = 0;  /* compression: deflate */
    ihdr[11] = 0;  /* filter method 0 */
    ihdr[12] = 0;  /* no interlace */

    f = fopen(path, "wb");
    if (!f) {
        status = -1;
    } else {
        if (fwrite(signature, 1, 8, f) != 8) status = -1;
        if (status == 0) status = pngw__chunk(f, "IHDR", ihdr, 13);
        if (status == 0) status = pngw__chunk(f, "IDAT", z, (uint32_t)(p - z));
        if (status == 0) status = pngw__chunk(f, "IEND", NULL, 0);
        if (fclose(f) != 0) status = -1;
    }
    free(raw);
    free(z);
    return status;
}

#endif /* PNG_WRITE_H */
