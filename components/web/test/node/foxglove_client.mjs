#!/usr/bin/env node
// A Foxglove client (npm @foxglove/ws-protocol, the one Foxglove ships) against dyad's bridge.
//
//   node foxglove_client.mjs watch URL TOPIC SECONDS OUT.json
//     lists the advertised channels, subscribes to TOPIC, decodes every frame with Foxglove's
//     omgidl parser + CDR reader, tries to publish on TOPIC (not writable: expects a status
//     error), and writes {channels, samples: [{seq, stamp, msg}], statuses} to OUT.json.
//   node foxglove_client.mjs compare OUT.json RECORDING.mcap TOPIC
//     checks that every sample the client got is in the recording with the same values
//     (matched by header.sequence_number); exits 1 on any difference.
import { readFile, writeFile, open } from "node:fs/promises";
import wsProtocol from "@foxglove/ws-protocol";
const { FoxgloveClient } = wsProtocol;
import WebSocket from "ws";
import { parseIDL } from "@foxglove/omgidl-parser";
import { MessageReader } from "@foxglove/omgidl-serialization";
import { McapIndexedReader } from "@mcap/core";
import { decompress } from "fzstd";

const bigintSafe = (_k, v) => (typeof v === "bigint" ? v.toString() : v);
const [mode, ...args] = process.argv.slice(2);

async function watch(url, topic, seconds, outFile) {
  const ws = new WebSocket(url, [FoxgloveClient.SUPPORTED_SUBPROTOCOL]);
  const client = new FoxgloveClient({ ws });
  const result = { channels: [], samples: [], statuses: [], serverInfo: null, errors: [] };
  const readers = new Map();
  let subscribed = false;
  client.on("serverInfo", (info) => (result.serverInfo = info));
  client.on("status", (s) => result.statuses.push(s));
  client.on("error", (e) => result.errors.push(String(e?.message ?? e)));
  client.on("advertise", (channels) => {
    for (const c of channels) {
      result.channels.push({ id: c.id, topic: c.topic, encoding: c.encoding, schemaName: c.schemaName, schemaEncoding: c.schemaEncoding });
      if (c.topic !== topic || subscribed) continue;
      readers.set(client.subscribe(c.id), new MessageReader(c.schemaName, parseIDL(c.schema)));
      subscribed = true;
      // Publishing on a topic the graph did not make writable must be refused with a status.
      client.advertise({ topic, encoding: "cdr", schemaName: c.schemaName });
    }
  });
  client.on("message", ({ subscriptionId, timestamp, data }) => {
    const reader = readers.get(subscriptionId);
    if (!reader) return;
    const msg = reader.readMessage(new Uint8Array(data.buffer, data.byteOffset, data.byteLength));
    result.samples.push({ seq: String(msg.header.sequence_number), stamp: String(timestamp), msg });
  });
  await new Promise((resolve) => setTimeout(resolve, seconds * 1000));
  client.close();
  await writeFile(outFile, JSON.stringify(result, bigintSafe, 1));
  process.stdout.write(`channels ${result.channels.length}, samples ${result.samples.length}, statuses ${result.statuses.length}\n`);
}

async function compare(outFile, mcapFile, topic) {
  const got = JSON.parse(await readFile(outFile, "utf8"));
  const handle = await open(mcapFile, "r");
  const reader = await McapIndexedReader.Initialize({
    readable: {
      size: async () => BigInt((await handle.stat()).size),
      read: async (offset, size) => {
        const b = new Uint8Array(Number(size));
        await handle.read(b, 0, b.length, Number(offset));
        return b;
      },
    },
    decompressHandlers: { zstd: (data, size) => decompress(data, new Uint8Array(Number(size))) },
  });
  const recorded = new Map();
  let channelReader = null;
  for (const ch of reader.channelsById.values()) {
    if (ch.topic !== topic) continue;
    const schema = reader.schemasById.get(ch.schemaId);
    channelReader = new MessageReader(schema.name, parseIDL(new TextDecoder().decode(schema.data)));
  }
  for await (const m of reader.readMessages({ topics: [topic] })) {
    const msg = channelReader.readMessage(m.data);
    recorded.set(String(msg.header.sequence_number), JSON.stringify(msg, bigintSafe));
  }
  let missing = 0, different = 0;
  for (const s of got.samples) {
    const r = recorded.get(s.seq);
    if (r === undefined) missing++;
    else if (r !== JSON.stringify(s.msg, bigintSafe)) different++;
  }
  process.stdout.write(`client samples ${got.samples.length}, recorded ${recorded.size}, missing ${missing}, different ${different}\n`);
  process.exit(got.samples.length > 0 && missing === 0 && different === 0 ? 0 : 1);
}

if (mode === "watch") await watch(args[0], args[1], Number(args[2]), args[3]);
else if (mode === "compare") await compare(args[0], args[1], args[2]);
else {
  process.stderr.write("usage: foxglove_client.mjs watch URL TOPIC SECONDS OUT.json | compare OUT.json REC.mcap TOPIC\n");
  process.exit(2);
}
