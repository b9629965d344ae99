// Reads a COPC file with copc.js (the npm package `copc`, by COPC's author; it decodes the chunks
// with laz-perf) and writes what it makes of the file as JSON: an independent reader's view of a
// file we wrote, for CopcJsReadsOurCopcTest to compare with what the indexer wrote.
//   node read-copc.js IN.copc.laz OUT.json
// OUT.json: {header, info, wkt, extraBytes, pages, nodes}. Every hierarchy page is walked, from
// the info VLR's root page down; each node lists its key, point count and chunk, and its
// points' dimensions, one array per dimension, as copc.js's view getters return them (X, Y, Z
// scaled by the header; ScanAngle in degrees). A double that JSON cannot hold exactly (NaN,
// infinities, -0) is written as the string "NaN", "Infinity", "-Infinity" or "-0", so that
// nothing is lost on the way. Prints one JSON line {nodes, points, pages}. Exits 1 with the
// reason on stderr when copc.js cannot read the file.
'use strict';

const fs = require('fs');
const { Copc } = require('copc');

// JSON.stringify writes the shortest decimal that reads back to the same double, but turns NaN
// and the infinities into null and -0 into 0.
function exact(value) {
    if (typeof value !== 'number') {
        return value;
    }
    if (Number.isNaN(value)) {
        return 'NaN';
    }
    if (!Number.isFinite(value)) {
        return value > 0 ? 'Infinity' : '-Infinity';
    }
    return Object.is(value, -0) ? '-0' : value;
}

// Walks the hierarchy from `page` and every page it points to; copc.js returns each page's
// nodes and the pages below it, keyed "level-x-y-z".
async function walkHierarchy(file, page, nodes, seenPages) {
    const key = `${page.pageOffset}+${page.pageLength}`;
    if (seenPages.has(key)) {
        throw new Error(`the hierarchy page at ${page.pageOffset} is listed twice`);
    }
    seenPages.add(key);
    const loaded = await Copc.loadHierarchyPage(file, page);
    for (const [nodeKey, node] of Object.entries(loaded.nodes)) {
        if (nodes.has(nodeKey)) {
            throw new Error(`node ${nodeKey} is listed twice in the hierarchy`);
        }
        nodes.set(nodeKey, node);
    }
    for (const child of Object.values(loaded.pages)) {
        await walkHierarchy(file, child, nodes, seenPages);
    }
}

async function main() {
    const [input, output] = process.argv.slice(2);
    if (!input || !output) {
        throw new Error('usage: node read-copc.js IN.copc.laz OUT.json');
    }
    const copc = await Copc.create(input);
    const { header, info } = copc;

    const hierarchy = new Map();
    const seenPages = new Set();
    await walkHierarchy(input, info.rootHierarchyPage, hierarchy, seenPages);

    const nodes = [];
    let points = 0;
    for (const [key, node] of hierarchy) {
        const entry = {
            key,
            pointCount: node.pointCount,
            pointDataOffset: node.pointDataOffset,
            pointDataLength: node.pointDataLength,
            dimensions: {},
        };
        // COPC allows nodes without points (their chunk is empty): nothing to decode there.
        if (node.pointCount > 0) {
            const view = await Copc.loadPointDataView(input, copc, node);
            if (view.pointCount !== node.pointCount) {
                throw new Error(`node ${key} decodes to ${view.pointCount} points, ` +
                                `its hierarchy entry says ${node.pointCount}`);
            }
            for (const name of Object.keys(view.dimensions)) {
                const get = view.getter(name);
                const values = new Array(view.pointCount);
                for (let i = 0; i < view.pointCount; ++i) {
                    values[i] = exact(get(i));
                }
                entry.dimensions[name] = values;
            }
        }
        points += node.pointCount;
        nodes.push(entry);
    }

    const result = {
        header: {
            majorVersion: header.majorVersion,
            minorVersion: header.minorVersion,
            pointDataRecordFormat: header.pointDataRecordFormat,
            pointDataRecordLength: header.pointDataRecordLength,
            pointCount: header.pointCount,
            pointCountByReturn: header.pointCountByReturn,
            scale: header.scale,
            offset: header.offset,
            min: header.min,
            max: header.max,
        },
        info: {
            cube: info.cube,
            spacing: info.spacing,
            rootHierarchyPage: info.rootHierarchyPage,
            gpsTimeRange: info.gpsTimeRange.map(exact),
        },
        wkt: copc.wkt === undefined ? null : copc.wkt,
        // The extra bytes' descriptors as copc.js reads them (the fields it decodes by name).
        extraBytes: copc.eb.map(({ name, type, length }) => ({ name, type: type || null, length })),
        pages: seenPages.size,
        nodes,
    };
    fs.writeFileSync(output, JSON.stringify(result));
    console.log(JSON.stringify({ nodes: nodes.length, points, pages: seenPages.size }));
}

main().catch((error) => {
    console.error(`copc.js cannot read the file: ${error && error.message ? error.message : error}`);
    process.exit(1);
});
