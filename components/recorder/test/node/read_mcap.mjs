#!/usr/bin/env node
// Reads an MCAP file with @mcap/core (Foxglove's reference TypeScript reader) and prints what it
// found as JSON, so tests can check dyad's writer against an independent implementation.
//
//   node read_mcap.mjs FILE                 indexed reader (footer + summary + chunk indexes)
//   node read_mcap.mjs --stream FILE        McapStreamReader (front to back; works on cut files)
//   ... --expect EXPECTED.json              also compare: every key in EXPECTED must match; exit 1
//                                           with the differences otherwise
//
// Output: header, schemas, channels (count, first/last log time, first/last sequence, sequence
// gaps, checksum = sum of CRC32 of every payload, bytes), metadata, totals. 64-bit times and sums
// are decimal strings (JSON numbers lose precision past 2^53).
import { open, readFile } from "node:fs/promises";
import { crc32 } from "@foxglove/crc";
import { McapIndexedReader, McapStreamReader } from "@mcap/core";
import { decompress } from "fzstd";

const decompressHandlers = {
  zstd: (data, size) => decompress(data, new Uint8Array(Number(size))),
};

function usage(message) {
  process.stderr.write(`${message}\nusage: node read_mcap.mjs [--stream] [--expect EXPECTED.json] FILE\n`);
  process.exit(2);
}

function parseArgs(argv) {
  const args = { stream: false, expect: undefined, file: undefined };
  for (let i = 0; i < argv.length; i++) {
    if (argv[i] === "--stream") args.stream = true;
    else if (argv[i] === "--expect") args.expect = argv[++i];
    else if (argv[i].startsWith("--")) usage(`unknown option ${argv[i]}`);
    else if (args.file === undefined) args.file = argv[i];
    else usage(`unexpected argument ${argv[i]}`);
  }
  if (!args.file) usage("missing FILE");
  return args;
}

// Accumulates per-channel facts from messages, whichever reader delivers them.
class Tally {
  constructor() {
    this.byChannel = new Map();
  }
  add(message) {
    let t = this.byChannel.get(message.channelId);
    if (!t) {
      t = { count: 0, first: undefined, last: undefined, sequences: [], checksum: 0n, bytes: 0 };
      this.byChannel.set(message.channelId, t);
    }
    t.count++;
    if (t.first === undefined || message.logTime < t.first) t.first = message.logTime;
    if (t.last === undefined || message.logTime > t.last) t.last = message.logTime;
    t.sequences.push(message.sequence);
    t.checksum += BigInt(crc32(message.data));
    t.bytes += message.data.byteLength;
  }
}

function summarize({ header, schemas, channels, metadata, tally, complete, reader }) {
  const schemaById = new Map(schemas.map((s) => [s.id, s]));
  const out = {
    reader,
    complete,
    profile: header?.profile ?? null,
    library: header?.library ?? null,
    message_count: 0,
    first_log_time: null,
    last_log_time: null,
    schemas: [...schemas]
      .sort((a, b) => a.id - b.id)
      .map((s) => ({ id: s.id, name: s.name, encoding: s.encoding, data: new TextDecoder().decode(s.data) })),
    channels: [],
    metadata: metadata.map((m) => ({ name: m.name, entries: Object.fromEntries([...m.metadata].sort()) })),
  };
  for (const c of [...channels].sort((a, b) => a.id - b.id)) {
    const t = tally.byChannel.get(c.id);
    const seqs = t ? [...new Set(t.sequences)].sort((a, b) => a - b) : [];
    const span = seqs.length ? seqs[seqs.length - 1] - seqs[0] + 1 : 0;
    out.channels.push({
      id: c.id,
      topic: c.topic,
      message_encoding: c.messageEncoding,
      schema_name: schemaById.get(c.schemaId)?.name ?? null,
      count: t?.count ?? 0,
      first_log_time: t ? String(t.first) : null,
      last_log_time: t ? String(t.last) : null,
      first_sequence: seqs.length ? seqs[0] : null,
      last_sequence: seqs.length ? seqs[seqs.length - 1] : null,
      sequence_gaps: span - seqs.length,
      duplicate_sequences: t ? t.sequences.length - seqs.length : 0,
      checksum: t ? String(t.checksum) : "0",
      bytes: t?.bytes ?? 0,
    });
    if (t) {
      out.message_count += t.count;
      if (out.first_log_time === null || t.first < BigInt(out.first_log_time)) out.first_log_time = String(t.first);
      if (out.last_log_time === null || t.last > BigInt(out.last_log_time)) out.last_log_time = String(t.last);
    }
  }
  return out;
}

async function readIndexed(file) {
  const handle = await open(file, "r");
  try {
    const readable = {
      size: async () => BigInt((await handle.stat()).size),
      read: async (offset, size) => {
        const buffer = new Uint8Array(Number(size));
        const { bytesRead } = await handle.read(buffer, 0, buffer.length, Number(offset));
        if (bytesRead !== buffer.length) throw new Error(`short read at ${offset}`);
        return buffer;
      },
    };
    const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
    const tally = new Tally();
    for await (const message of reader.readMessages({ validateCrcs: true })) tally.add(message);
    const metadata = [];
    for await (const m of reader.readMetadata()) metadata.push(m);
    const result = summarize({
      reader: "indexed",
      complete: true,
      header: reader.header,
      schemas: [...reader.schemasById.values()],
      channels: [...reader.channelsById.values()],
      metadata,
      tally,
    });
    result.statistics_message_count = reader.statistics ? String(reader.statistics.messageCount) : null;
    result.chunk_count = reader.chunkIndexes.length;
    return result;
  } finally {
    await handle.close();
  }
}

// Feeds the whole file to McapStreamReader; a cut file simply never reaches the footer.
async function readStream(file) {
  const bytes = new Uint8Array(await readFile(file));
  const reader = new McapStreamReader({ decompressHandlers, validateCrcs: true });
  reader.append(bytes);
  let header;
  const schemas = new Map();
  const channels = new Map();
  const metadata = [];
  const tally = new Tally();
  let error = null;
  try {
    for (let record; (record = reader.nextRecord()); ) {
      switch (record.type) {
        case "Header": header = record; break;
        case "Schema": schemas.set(record.id, record); break;
        case "Channel": channels.set(record.id, record); break;
        case "Metadata": metadata.push(record); break;
        case "Message": tally.add(record); break;
        default: break;
      }
    }
  } catch (e) {
    error = String(e?.message ?? e);
  }
  const result = summarize({
    reader: "stream",
    complete: reader.done(),
    header,
    schemas: [...schemas.values()],
    channels: [...channels.values()],
    metadata,
    tally,
  });
  result.unparsed_bytes = reader.bytesRemaining();
  result.error = error;
  return result;
}

// Lists every path where `actual` differs from `expected` (keys absent from `expected` are free).
function differences(expected, actual, path = "") {
  if (expected !== null && typeof expected === "object") {
    if (actual === null || typeof actual !== "object" || Array.isArray(expected) !== Array.isArray(actual)) {
      return [`${path || "/"}: expected ${JSON.stringify(expected)}, got ${JSON.stringify(actual)}`];
    }
    if (Array.isArray(expected) && expected.length !== actual.length) {
      return [`${path}: expected ${expected.length} entries, got ${actual.length}`];
    }
    return Object.keys(expected).flatMap((k) => differences(expected[k], actual[k], `${path}/${k}`));
  }
  return expected === actual ? [] : [`${path}: expected ${JSON.stringify(expected)}, got ${JSON.stringify(actual)}`];
}

const args = parseArgs(process.argv.slice(2));
let result;
try {
  result = args.stream ? await readStream(args.file) : await readIndexed(args.file);
} catch (e) {
  process.stderr.write(`read_mcap.mjs: ${args.file}: ${e?.stack ?? e}\n`);
  process.exit(1);
}
process.stdout.write(JSON.stringify(result, null, 2) + "\n");
if (args.expect) {
  const expected = JSON.parse(await readFile(args.expect, "utf8"));
  const diffs = differences(expected, result);
  if (diffs.length) {
    process.stderr.write(`read_mcap.mjs: ${args.file} differs from ${args.expect}:\n  ${diffs.join("\n  ")}\n`);
    process.exit(1);
  }
  process.stderr.write(`read_mcap.mjs: ${args.file}: matches ${args.expect} (${result.message_count} messages)\n`);
}
