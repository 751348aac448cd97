#!/usr/bin/env node
// Decodes every message of an MCAP recording the way Foxglove does: each channel's omgidl schema
// is parsed by @foxglove/omgidl-parser and its CDR messages are read by
// @foxglove/omgidl-serialization's MessageReader. Proof that a dyad recording opens in Foxglove.
//
//   node decode_omgidl.mjs FILE
// Prints JSON: per channel the topic, schema name, decoded count, failures (with the first error),
// and the first decoded message; exits 1 if a schema does not parse or a message does not decode,
// or if a message's header.sequence_number differs from the MCAP record's sequence.
import { open } from "node:fs/promises";
import { McapIndexedReader } from "@mcap/core";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import { decompress } from "fzstd";

const file = process.argv[2];
if (!file) {
  process.stderr.write("usage: node decode_omgidl.mjs FILE\n");
  process.exit(2);
}
const handle = await open(file, "r");
const readable = {
  size: async () => BigInt((await handle.stat()).size),
  read: async (offset, size) => {
    const buffer = new Uint8Array(Number(size));
    await handle.read(buffer, 0, buffer.length, Number(offset));
    return buffer;
  },
};
const reader = await McapIndexedReader.Initialize({
  readable,
  decompressHandlers: { zstd: (data, size) => decompress(data, new Uint8Array(Number(size))) },
});
const readers = new Map();
const out = new Map();
let bad = 0;
for (const channel of reader.channelsById.values()) {
  const schema = reader.schemasById.get(channel.schemaId);
  const entry = { topic: channel.topic, schema: schema?.name ?? null, decoded: 0, failures: 0, first_error: null, sequence_mismatches: 0, first: null };
  out.set(channel.id, entry);
  try {
    if (!schema || schema.encoding !== "omgidl" || channel.messageEncoding !== "cdr") throw new Error("not omgidl/cdr");
    const definitions = parseIDL(new TextDecoder().decode(schema.data));
    readers.set(channel.id, new MessageReader(schema.name, definitions));
  } catch (e) {
    entry.first_error = `schema: ${e?.message ?? e}`;
    bad++;
  }
}
const bigintSafe = (_k, v) => (typeof v === "bigint" ? v.toString() : v);
for await (const m of reader.readMessages()) {
  const r = readers.get(m.channelId);
  const entry = out.get(m.channelId);
  if (!r) continue;
  try {
    const msg = r.readMessage(m.data);
    entry.decoded++;
    if (entry.first === null) entry.first = JSON.parse(JSON.stringify(msg, bigintSafe));
    const seq = msg?.header?.sequence_number;
    if (seq !== undefined && BigInt(seq) % 4294967296n !== BigInt(m.sequence)) entry.sequence_mismatches++;
  } catch (e) {
    entry.failures++;
    entry.first_error ??= String(e?.message ?? e);
  }
}
await handle.close();
const channels = [...out.values()];
for (const c of channels) if (c.failures > 0 || c.sequence_mismatches > 0) bad++;
process.stdout.write(JSON.stringify({ file, channels }, null, 2) + "\n");
process.exit(bad > 0 ? 1 : 0);
