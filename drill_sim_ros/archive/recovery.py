"""Damage-tolerant framing of an MCAP file: every intact record, and what was skipped.

An MCAP file is a sequence of records ``opcode (1 byte) | length (u64) | content``. A damaged
record (flipped bytes, a cut) is skipped and the scan resumes at the next record that is
provably intact: the one right after the damaged record if that one parses (its length field
survived), else the next Chunk found by scanning whose decompressed content matches its CRC.
Each skipped stretch becomes a :class:`Damage` with its byte range, the log times its chunk
header states, and the messages it held when the MessageIndex records after it say so.
"""

from __future__ import annotations

import io
import mmap
import struct
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import zstandard
from mcap.data_stream import ReadDataStream
from mcap.exceptions import EndOfFile, McapError
from mcap.opcode import Opcode
from mcap.records import (
    Attachment,
    AttachmentIndex,
    Channel,
    Chunk,
    ChunkIndex,
    DataEnd,
    Footer,
    Header,
    Message,
    MessageIndex,
    Metadata,
    MetadataIndex,
    Schema,
    Statistics,
    SummaryOffset,
)
from mcap.stream_reader import breakup_chunk

MAGIC_SIZE = 8
FRAME_SIZE = 9                         # opcode + u64 length
# No record we write comes near this; a larger length field means corruption.
RECORD_SIZE_LIMIT = 256 * 1024 * 1024
# What damaged bytes raise inside mcap's parsers (CRC errors are ValueErrors).
DAMAGE = (McapError, ValueError, struct.error, zstandard.ZstdError, RuntimeError, MemoryError,
          UnicodeDecodeError, EndOfFile, OverflowError, IndexError, KeyError)

_READERS: dict[int, Callable[[ReadDataStream, int], object]] = {
    Opcode.ATTACHMENT: lambda s, n: Attachment.read(s),
    Opcode.ATTACHMENT_INDEX: lambda s, n: AttachmentIndex.read(s),
    Opcode.CHANNEL: lambda s, n: Channel.read(s),
    Opcode.CHUNK: lambda s, n: Chunk.read(s),
    Opcode.CHUNK_INDEX: lambda s, n: ChunkIndex.read(s),
    Opcode.DATA_END: lambda s, n: DataEnd.read(s),
    Opcode.FOOTER: lambda s, n: Footer.read(s),
    Opcode.HEADER: lambda s, n: Header.read(s),
    Opcode.MESSAGE: lambda s, n: Message.read(s, n),
    Opcode.MESSAGE_INDEX: lambda s, n: MessageIndex.read(s),
    Opcode.METADATA: lambda s, n: Metadata.read(s),
    Opcode.METADATA_INDEX: lambda s, n: MetadataIndex.read(s),
    Opcode.SCHEMA: lambda s, n: Schema.read(s),
    Opcode.STATISTICS: lambda s, n: Statistics.read(s),
    Opcode.SUMMARY_OFFSET: lambda s, n: SummaryOffset.read(s),
}


@dataclass
class Damage:
    """A skipped stretch of the file: bytes [start, end), and what it held if known."""

    start: int
    end: int
    reason: str
    messages: int | None = None
    log_start_ns: int | None = None
    log_end_ns: int | None = None
    at_end: bool = False                  # nothing intact follows (a cut file)
    in_summary: bool = False              # after DataEnd: no message was lost with it

    def describe(self) -> str:
        held = "" if self.messages is None else f", {self.messages} messages"
        times = ""
        if self.log_start_ns is not None:
            times = (f", log time {self.log_start_ns / 1e9:.3f}-"
                     f"{(self.log_end_ns or self.log_start_ns) / 1e9:.3f} s")
        return f"bytes {self.start}-{self.end} ({self.reason}{held}{times})"


@dataclass
class Scan:
    """What a scan met: the intact records are yielded, the rest is listed here."""

    damage: list[Damage] = field(default_factory=list)
    footer: bool = False
    in_summary: bool = False


class _Exact(io.BytesIO):
    """A record's content: a read past its end is damage, never a half-parsed record."""

    def read(self, size: int | None = -1) -> bytes:
        data = super().read(size)
        if size is not None and size >= 0 and len(data) < size:
            raise EndOfFile()
        return data


def parse_record(opcode: int, content: bytes) -> object:
    """One record from its content bytes (raises one of DAMAGE if they do not parse)."""
    reader = _READERS.get(opcode)
    if reader is None:
        raise McapError(f"unknown opcode 0x{opcode:02x}")
    stream = ReadDataStream(_Exact(content))
    record = reader(stream, len(content))
    if stream.count > len(content):
        raise McapError("record overruns its length")
    return record


def chunk_records(chunk: Chunk) -> list[object]:
    """The records inside ``chunk``, its CRC checked (raises one of DAMAGE)."""
    if chunk.uncompressed_size > RECORD_SIZE_LIMIT:
        raise McapError(f"chunk claims {chunk.uncompressed_size} bytes uncompressed")
    return breakup_chunk(chunk, validate_crc=True)


class RecordScanner:
    """Scans ``data`` (the whole file, e.g. an mmap) from after the magic."""

    def __init__(self, data: mmap.mmap | bytes) -> None:
        self._data = data
        self._size = len(data)
        self.scan = Scan()

    # ---- framing ------------------------------------------------------------------------
    def _frame(self, pos: int) -> tuple[int, object] | None:
        """(end, record) if an intact record starts at ``pos``, else None."""
        if pos + FRAME_SIZE > self._size:
            return None
        opcode = self._data[pos]
        (length,) = struct.unpack_from("<Q", self._data, pos + 1)
        end = pos + FRAME_SIZE + length
        if opcode not in _READERS or length > RECORD_SIZE_LIMIT or end > self._size:
            return None
        try:
            return end, parse_record(opcode, bytes(self._data[pos + FRAME_SIZE:end]))
        except DAMAGE:
            return None

    def _intact_chunk_at(self, pos: int) -> tuple[int, Chunk] | None:
        framed = self._frame(pos)
        if framed is None or not isinstance(framed[1], Chunk):
            return None
        try:
            chunk_records(framed[1])
        except DAMAGE:
            return None
        return framed  # type: ignore[return-value]

    def _resync(self, pos: int) -> int | None:
        """The offset of the next intact chunk (or DataEnd) after ``pos``, else None."""
        data, chunk_op, end_op = self._data, bytes([Opcode.CHUNK]), bytes([Opcode.DATA_END])
        candidate = pos
        while True:
            hits = [i for i in (data.find(chunk_op, candidate), data.find(end_op, candidate))
                    if i >= 0]
            if not hits:
                return None
            candidate = min(hits)
            if data[candidate] == Opcode.CHUNK and self._intact_chunk_at(candidate):
                return candidate
            if data[candidate] == Opcode.DATA_END and self._is_data_end(candidate):
                return candidate
            candidate += 1

    def _is_data_end(self, pos: int) -> bool:
        framed = self._frame(pos)
        return framed is not None and isinstance(framed[1], DataEnd) and \
            self._frame(framed[0]) is not None

    def _chunk_header(self, pos: int) -> tuple[int, int] | None:
        """The log times a (possibly damaged) chunk header at ``pos`` claims, if sane."""
        if self._size < pos + FRAME_SIZE + 16 or self._data[pos] != Opcode.CHUNK:
            return None
        start, end = struct.unpack_from("<QQ", self._data, pos + FRAME_SIZE)
        return (start, end) if start <= end else None

    # ---- records ------------------------------------------------------------------------
    def records(self, start: int = MAGIC_SIZE) -> Iterator[object]:
        """Every intact record in file order, chunks broken up; damage goes to ``scan``."""
        pos = start
        while pos < self._size:
            framed = self._frame(pos)
            if framed is None:
                pos = self._skip(pos, "unreadable record")
                continue
            end, record = framed
            if isinstance(record, Chunk):
                try:
                    inner = chunk_records(record)
                except DAMAGE as exc:
                    pos = self._skip_chunk(pos, end, record, exc)
                    continue
                yield from inner
            else:
                self.scan.in_summary |= isinstance(record, DataEnd)
                yield record
                if isinstance(record, Footer):
                    self.scan.footer = True
                    return
            pos = end

    def _skip(self, pos: int, reason: str) -> int:
        """Record damage from ``pos`` to the next intact chunk; returns where to go on."""
        resume = self._resync(pos + 1)
        times = self._chunk_header(pos)
        damage = Damage(pos, self._size if resume is None else resume,
                        "cut short" if resume is None else reason, None,
                        *(times or (None, None)), at_end=resume is None,
                        in_summary=self.scan.in_summary)
        self.scan.damage.append(damage)
        return self._size if resume is None else resume

    def _skip_chunk(self, pos: int, end: int, chunk: Chunk,
                    exc: BaseException) -> int:
        """A chunk whose frame is intact but whose content is not (CRC, decompression)."""
        if self._frame(end) is None and self._size > end:
            return self._skip(pos, f"damaged chunk: {_short(exc)}")
        damage = Damage(pos, end, f"damaged chunk: {_short(exc)}", None,
                        chunk.message_start_time, chunk.message_end_time)
        self.scan.damage.append(damage)
        damage.messages = self._indexed_messages(end)
        return end

    def _indexed_messages(self, pos: int) -> int | None:
        """Messages listed by the MessageIndex records at ``pos`` (after a chunk)."""
        count, seen = 0, False
        while (framed := self._frame(pos)) is not None and isinstance(framed[1], MessageIndex):
            count += len(framed[1].records)
            seen, pos = True, framed[0]
        return count if seen else None


def _short(exc: BaseException) -> str:
    text = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
    return text[:120]
