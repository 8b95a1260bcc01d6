// Independent check of an MCAP file with the official TypeScript library, @mcap/core.
//
//   node tests/support/mcap_check.mjs FILE
//
// prints one line of JSON on stdout:
//   {complete, messageCount, channels: [topics], schemas: [names], ...}
// - McapIndexedReader opens the file from its end (trailing magic, Footer, summary with
//   its CRC, Statistics, Chunk Indexes, Summary Offsets), as Foxglove and Lichtblick do, and
//   reads every message through the Chunk Index and Message Index records, checking each
//   chunk's CRC ("indexed.messageCount"; 0 for a file without chunks, whose messages no
//   index finds). It fails on a truncated file; its error is reported as "indexError" and
//   is not fatal.
// - McapStreamReader reads every record from the front, validating each (a chunk's CRC
//   too); it gives the message count, and done() says whether the file ended with a Footer
//   and the magic.
// complete = the indexed reader opened the file and the stream reader finished it.
// Exit status: 0 when the file was read (complete or not), 1 when a reader rejected it,
// 2 on bad usage, 3 when @mcap/core is not installed (npm install --prefix deploy/node).
//
// @mcap/core is found under deploy/node/node_modules of the source tree (two folders up
// from this script), or under $COHAPTIC_NODE_DIR/node_modules if that is set.
import { readFileSync } from "node:fs";
import { createRequire } from "node:module";
import path from "node:path";
import { fileURLToPath } from "node:url";
import zlib from "node:zlib";

const here = path.dirname(fileURLToPath(import.meta.url));
const nodeDir = process.env.COHAPTIC_NODE_DIR ?? path.resolve(here, "../../deploy/node");

let mcap;
try {
  mcap = createRequire(path.join(nodeDir, "package.json"))("@mcap/core");
} catch (error) {
  console.error(`@mcap/core not found under ${nodeDir}/node_modules (${error.message}); ` +
    "install it with: npm install --prefix deploy/node");
  process.exit(3);
}

if (process.argv.length !== 3) {
  console.error("usage: node mcap_check.mjs FILE");
  process.exit(2);
}
const file = process.argv[2];

const toNumber = (value) => (typeof value === "bigint" ? Number(value) : value);

async function check() {
  const bytes = readFileSync(file);
  const result = {
    file,
    complete: false,
    messageCount: 0,
    channels: [],
    schemas: [],
    channelMessageCounts: {},
    library: null,
    indexed: null,
    indexError: null,
  };

  let indexed;
  try {
    indexed = await mcap.McapIndexedReader.Initialize({
      readable: {
        size: async () => BigInt(bytes.byteLength),
        read: async (offset, size) => bytes.subarray(Number(offset), Number(offset) + Number(size)),
      },
    });
  } catch (error) {
    result.indexError = error.message;
  }
  if (indexed) {
    const topicOf = (id) => indexed.channelsById.get(id)?.topic ?? `#${id}`;
    const statistics = indexed.statistics;
    const dataEnd = toNumber(indexed.dataEndOffset);
    let indexedMessages = 0;
    const indexedChannelMessageCounts = {};
    for await (const message of indexed.readMessages({ validateCrcs: true })) {
      indexedMessages += 1;
      const topic = topicOf(message.channelId);
      indexedChannelMessageCounts[topic] = (indexedChannelMessageCounts[topic] ?? 0) + 1;
    }
    result.indexed = {
      channels: [...indexed.channelsById.values()].map((c) => c.topic).sort(),
      schemas: [...indexed.schemasById.values()].map((s) => s.name).sort(),
      chunkCount: indexed.chunkIndexes.length,
      messageCount: indexedMessages,
      channelMessageCounts: indexedChannelMessageCounts,
      summaryOffsetOpcodes: [...indexed.summaryOffsetsByOpcode.keys()].sort((a, b) => a - b),
      statistics: statistics
        ? {
            messageCount: toNumber(statistics.messageCount),
            schemaCount: statistics.schemaCount,
            channelCount: statistics.channelCount,
            messageStartTime: String(statistics.messageStartTime),
            messageEndTime: String(statistics.messageEndTime),
            channelMessageCounts: Object.fromEntries(
              [...statistics.channelMessageCounts.entries()].map(([id, n]) => [topicOf(id), toNumber(n)]),
            ),
          }
        : null,
      // The data-section CRC, recomputed here with Node's zlib (not by @mcap/core).
      dataSectionCrcOk:
        indexed.dataSectionCrc === undefined || typeof zlib.crc32 !== "function"
          ? null
          : zlib.crc32(bytes.subarray(0, dataEnd)) === indexed.dataSectionCrc,
    };
  }

  const stream = new mcap.McapStreamReader({ validateCrcs: true });
  stream.append(bytes);
  const topics = new Map();
  const schemas = new Map();
  for (let record; (record = stream.nextRecord()); ) {
    switch (record.type) {
      case "Header":
        result.library = record.library;
        break;
      case "Schema":
        schemas.set(record.id, record.name);
        break;
      case "Channel":
        topics.set(record.id, record.topic);
        break;
      case "Message": {
        result.messageCount += 1;
        const topic = topics.get(record.channelId);
        result.channelMessageCounts[topic] = (result.channelMessageCounts[topic] ?? 0) + 1;
        break;
      }
      default:
        break;
    }
  }
  result.channels = [...new Set(topics.values())].sort();
  result.schemas = [...new Set(schemas.values())].sort();
  result.complete = indexed !== undefined && stream.done();
  return result;
}

try {
  console.log(JSON.stringify(await check()));
} catch (error) {
  console.log(JSON.stringify({ file, error: error.message }));
  process.exit(1);
}
