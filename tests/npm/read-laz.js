// Reads a LAZ file with laz-perf (LASzip's decoder compiled to WebAssembly) and writes its point
// records, decompressed, to a file: what an independent reader makes of a file we wrote.
//   node read-laz.js IN.laz OUT.records
// Prints one JSON line: {"pointFormat", "pointLength", "pointCount"}. Exits 1 with the reason on
// stderr when laz-perf cannot read the file.
'use strict';

const fs = require('fs');
const { createLazPerf } = require('laz-perf');

async function main() {
    const [input, output] = process.argv.slice(2);
    if (!input || !output) {
        throw new Error('usage: node read-laz.js IN.laz OUT.records');
    }
    const file = fs.readFileSync(input);
    const LazPerf = await createLazPerf();
    const reader = new LazPerf.LASZip();
    // laz-perf reads from and decodes into its own (WebAssembly) heap.
    const filePointer = LazPerf._malloc(file.byteLength);
    let pointPointer = 0;
    try {
        LazPerf.HEAPU8.set(file, filePointer);
        reader.open(filePointer, file.byteLength);
        const pointFormat = reader.getPointFormat();
        const pointLength = reader.getPointLength();
        const pointCount = reader.getCount();
        pointPointer = LazPerf._malloc(pointLength);
        const records = Buffer.alloc(pointLength * pointCount);
        for (let i = 0; i < pointCount; ++i) {
            reader.getPoint(pointPointer);
            // The heap may have grown (and moved) during the call: view it afresh.
            records.set(LazPerf.HEAPU8.subarray(pointPointer, pointPointer + pointLength),
                        i * pointLength);
        }
        fs.writeFileSync(output, records);
        console.log(JSON.stringify({ pointFormat, pointLength, pointCount }));
    } finally {
        if (pointPointer) {
            LazPerf._free(pointPointer);
        }
        LazPerf._free(filePointer);
        reader.delete();
    }
}

main().catch((error) => {
    console.error(`laz-perf cannot read the file: ${error && error.message ? error.message : error}`);
    process.exit(1);
});
